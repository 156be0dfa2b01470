"""Synthesis F: tailor measurements -> mannequin (paper, Section 2.3.6), plus an exact refinement.

**Segmented IDW** (Eq. 2.1, p = 2 by default). Every ellipsoid is a weighted mean of its five
counterparts in the Reference Mannequins (RMs); the weights are inverse distances between the
request and each RM's measurements, taken only over the measurements that ellipsoid depends on
(``Topology.dependency_mask``). Centres and semi-axes are averaged linearly, rotations by the
chordal mean projected back to SO(3) (``frames.rotation_mean``). At an RM's own measurements the
distance is 0 and the result is that RM.

One refinement of the paper's formula: RMs that coincide in an ellipsoid's sub-space (Table 2.3 has
Small Slim and Small Chubby both at He = 148, so a head that depends on He alone cannot tell them
apart) keep the paper's total weight for the group but share it by IDW in the full measurement space,
instead of in equal parts. Nothing changes where no two RMs coincide; it keeps F continuous and makes
it reproduce every RM exactly, head included.

Only the left and central ellipsoids are interpolated; the right ones are their sagittal mirrors with
the axis signs the RMs use, so every result is exactly symmetric and exact at the RMs.

**Proportional IDW** (``normalize="proportional"``, the default; ``"none"`` is the paper's Eq. 2.1).
Plain IDW places a part that depends on (He, Br) as the RMs nearest in (He, Br) are, so its height is
their weighted mean He, not the request's (about 2% off on the 243 grid), and the section at
0.72 He cuts the chest in the wrong place; and a weighted mean of the RMs' Br is not the requested Br
(IDW does not reproduce linear functions). So each RM's part is first divided by that RM's own
scales, the same IDW weights average these proportions, and the mean is multiplied by the request's
scales: heights (centre z above the floor, vertical semi-axes) by He, widths (centre x and y about
the registration origin, horizontal semi-axes) by the part's own measurement (Br for the chest, Sh
for shoulders and arms, ...; parts on He alone keep their widths). Scales are relative to the mean
of the RMs' measurements; a semi-axis tilted from the vertical takes vertical^v * horizontal^(1-v),
v its share along z, so rotations are untouched (the same mean rotations as the paper's).
The limbs are the exception: scaling widths and heights apart in the world's axes would turn them (it leaned
the female set's arms anywhere from 29.9 to 41.4 degrees from the vertical, the RMs' 35.2-35.3, and narrowed a
tall, narrow request's stance), so a part on an arm or a leg (``skeleton.LIMBS``) is anchored at its limb's root
joint (the shoulder, the hip), which scales as any centre, and its offset from that joint scales in the limb's
own axes: by the height along the limb, by the width across it; so do the limb's joints, and a limb's semi-axis
takes the height by its share along the limb. The limbs then lean as the RMs' do (docs/synthesis.md).
``"height"`` scales heights only (and a limb along its length). At an RM's measurements the scales cancel and
the result is the RM; the weights are the paper's; what is bounded by the RMs is the proportions, not the
geometry itself (a request outside L is scaled beyond the RMs).

**Exact mode** (beyond the paper): IDW is a weighted mean, so m_T of its result misses the request
(the paper's by a few percent, Table 2.4; proportional IDW by less). ``refine`` then deforms the
mannequin gently until m_T matches: five factors, solved by quasi-Newton steps on log m_T (starting
from the RMs' mean Jacobian, Broyden updates):

- He: vertical stretch about the floor (centres' z, and each semi-axis by its vertical share);
- Br, Wa, Hi: horizontal scaling of the girth ellipsoids about the body's vertical axis, blended
  with height by hat functions peaking at each section, so neighbouring parts move together;
- Sh: the shoulder ellipsoids (those that depend on Sh) widen along x; the arms hanging from them
  (non-girth parts that depend on Sh) are carried sideways by the same amount, not thickened.

The code: requests in ``core.synthesis.request``, the Reference Mannequins in ``core.synthesis.reference_set``, IDW in
``core.synthesis.idw``, the refinement in ``core.synthesis.refine``, the options in ``core.synthesis.options``; this
module puts them together and keeps their names importable from here.
"""

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..constants import CENTER_LIMIT, FEMALE_SET, SEMI_AXIS_LIMITS
from ..errors import ElliMannError, MannequinError
from ..mannequin.joints import anchor_indices, follow_pieces
from ..mannequin.model import Mannequin
from ..measure.extra import mannequin_extra_measurements
from ..measure.tailor import as_dict, followed_measurements, tailor_measurements
from ..measurements import MEASUREMENTS
from .extra_refine import ExtraRequestError, extra_request_problems, meet_extra
from .idw import idw_weights, interpolate, interpolate_joints
from .misses import missed_text, request_misses
from .options import (
    DEFAULT_NORMALIZE,
    DEFAULT_POWER,
    METRICS,
    MODES,
    NORMALIZATIONS,
    PAPER_NORMALIZE,
    POWER_LIMITS,
    SynthesisOptions,
    check_options,
)
from .reference_set import REFERENCE_FOLDER, REFERENCE_NAMES, ReferenceSet, cached_reference_set, load_reference_set
from .refine import EXACT_MAX_ITERATIONS, EXACT_TOLERANCE, FACTOR_LIMITS, Refinement, deform, refine
from .request import (
    checked_request,
    mannequin_name,
    relative_error,
    request_array,
    validate_request,
    validate_requests,
)

__all__ = [
    "DEFAULT_NORMALIZE",
    "DEFAULT_POWER",
    "EXACT_MAX_ITERATIONS",
    "EXACT_TOLERANCE",
    "FACTOR_LIMITS",
    "METRICS",
    "MODES",
    "NORMALIZATIONS",
    "PAPER_NORMALIZE",
    "POWER_LIMITS",
    "REFERENCE_FOLDER",
    "REFERENCE_NAMES",
    "ReferenceSet",
    "Refinement",
    "SynthesizedBatch",
    "SynthesisOptions",
    "Synthesized",
    "cached_reference_set",
    "check_options",
    "check_plausible",
    "deform",
    "idw_weights",
    "interpolate",
    "load_reference_set",
    "mannequin_name",
    "meet_extra_request",
    "options_of",
    "refine",
    "relative_error",
    "request_array",
    "synthesize",
    "synthesize_batch",
    "synthesize_checked",
    "synthesize_extra",
    "validate_request",
    "validate_requests",
]


@dataclass
class SynthesizedBatch:
    """A batch of synthesized mannequins sharing the reference set's topology (and its section heights)."""

    topology: object
    requests: np.ndarray  # (B, 5) cm
    rotation: np.ndarray  # (B, n, 3, 3)
    center: np.ndarray  # (B, n, 3)
    semi_axes: np.ndarray  # (B, n, 3)
    measured: np.ndarray  # (B, 5) cm, m_T of each result (None if not measured)
    factors: np.ndarray  # (B, 5) exact-mode deformation factors (ones for IDW)
    converged: np.ndarray  # (B,) exact mode reached its tolerance (True for IDW)
    mode: str
    reference_set: str = FEMALE_SET  # the name of the set they come from
    section_fractions: dict = None  # the set's section heights (None: SECTION_FRACTIONS)
    joints: np.ndarray = None  # (B, 24, 3) rest joints (core.mannequin.joints), None if the RMs have none
    errors: list = None  # per row: None, or why that row failed (its arrays are then NaN); None: none failed
    # (B, 6) cm: the extra measurements (EXTRA_MEASUREMENTS order) of the rows that asked for some, NaN elsewhere
    # (core.synthesis.batch.synthesize_chunk); None: no row asked
    extra_measured: np.ndarray = None

    def __len__(self):
        return len(self.requests)

    def error(self, i):
        """Why row ``i`` failed, or None."""
        return None if self.errors is None else self.errors[i]

    def mannequin(self, i, name=None):
        me = as_dict(self.requests[i])
        return Mannequin(
            self.topology,
            self.rotation[i],
            self.center[i],
            self.semi_axes[i],
            name=name or mannequin_name(me),
            role="synthesized",
            measurements=me,
            reference_set=self.reference_set,
            section_fractions=self.section_fractions,
            joints=None if self.joints is None else self.joints[i],
        )

    def relative_error(self):
        """(B, 5) |m_T - request| / request in % (:func:`relative_error`)."""
        return relative_error(self.measured, self.requests)


def check_plausible(topology, requests, rotation, center, semi_axes):
    """Refuse synthesis results (B, n, ...) with a piece outside the plausibility limits (SEMI_AXIS_LIMITS,
    CENTER_LIMIT) or not finite, as a file or a collection holding them would be: ElliMannError naming the
    request, the part, the field and the range. A few whole-array reductions (NaN fails them all); only when one
    fails, the test per piece and ``Mannequin.problems`` of the first bad result for the message."""
    low, high = SEMI_AXIS_LIMITS
    with np.errstate(invalid="ignore"):
        if (
            np.min(semi_axes, initial=np.inf) >= low
            and np.max(semi_axes, initial=-np.inf) <= high
            and np.max(np.abs(center), initial=0.0) <= CENTER_LIMIT
            and np.isfinite(np.max(np.abs(rotation), initial=0.0))
        ):
            return
        good = (
            np.all(np.isfinite(semi_axes), axis=-1)
            & np.all((semi_axes >= low) & (semi_axes <= high), axis=-1)
            & np.all(np.isfinite(center), axis=-1)
            & np.all(np.abs(center) <= CENTER_LIMIT, axis=-1)
            & np.all(np.isfinite(rotation), axis=(-1, -2))
        )
    row = int(np.argwhere(~good)[0][0])
    mannequin = Mannequin(topology, rotation[row], center[row], semi_axes[row])
    problems = [p for p in mannequin.problems() if p.field in ("rotation", "center", "semi_axes")]
    request = ", ".join(f"{k} {v:g}" for k, v in zip(MEASUREMENTS, requests[row]))
    raise ElliMannError(f"synthesis at {request} cm gives an implausible mannequin: {MannequinError(problems)}")


def options_of(options=None, **fields):
    """``options`` (a SynthesisOptions, default ``SynthesisOptions()``) with ``fields`` (mode=, metric=, power=,
    normalize=, name=) replaced."""
    if options is None:
        options = SynthesisOptions()
    elif not isinstance(options, SynthesisOptions):
        raise TypeError(
            f"options must be a SynthesisOptions (mode, metric, power, normalize by keyword), got {options!r}"
        )
    return options.replace(**fields) if fields else options


def synthesize_batch(reference, requests, options=None, *, measure=True, tolerance=EXACT_TOLERANCE, **fields):
    """Synthesize many mannequins at once: requests (B, 5) cm -> SynthesizedBatch with (B, n, ...) arrays.

    ``options``: a SynthesisOptions (default: exact mode, ``options.SYNTHESIS``); keywords mode=, metric=,
    power=, normalize= replace its fields. The paper's method is ``mode="idw", normalize="none"`` (with the
    default raw metric and p = 2; ``options.PAPER``). The requests and options are checked here, where they enter
    (:func:`synthesize_checked` takes them checked).
    """
    options = options_of(options, **fields).checked()
    requests = validate_requests(requests, reference.ranges, reference.absurd_limits)
    return synthesize_checked(reference, requests, options, measure=measure, tolerance=tolerance)


def synthesize_checked(reference, requests, options, *, measure=True, tolerance=EXACT_TOLERANCE):
    """:func:`synthesize_batch` of requests (B, 5) float array and options already checked where they entered
    (``validate_requests`` or ``checked_request``; ``SynthesisOptions.checked``)."""
    mode = options.mode
    weights = idw_weights(reference, requests, options.metric, options.power)  # for the pieces and the joints alike
    rotation, center, semi_axes = interpolate(
        reference, requests, options.metric, options.power, options.normalize, weights
    )
    joints = interpolate_joints(reference, requests, options.metric, options.power, options.normalize, weights)
    girth = reference.topology.girth_mask
    fractions = reference.section_fractions
    measured, structure = None, None
    if mode == "exact":  # the start's girth sections' structure too, for the refinement's steps to follow
        measured, structure = followed_measurements(rotation, center, semi_axes, girth, fractions)
    elif measure:
        measured = tailor_measurements(rotation, center, semi_axes, girth, fractions)
    factors = np.ones_like(requests)
    converged = np.ones(len(requests), dtype=bool)
    if mode == "exact":
        result = refine(
            reference.topology,
            rotation,
            center,
            semi_axes,
            requests,
            measured,
            tolerance,
            jacobian=reference.refine_jacobian(),
            fractions=fractions,
            structure=structure,
        )
        if joints is not None:  # the joints move with their anchor pieces
            joints = follow_pieces(
                joints,
                anchor_indices(reference.topology),
                (rotation, center, semi_axes),
                (rotation, result.center, result.semi_axes),
            )
        center, semi_axes, measured = result.center, result.semi_axes, result.measured
        factors, converged = result.factors, result.converged
    check_plausible(reference.topology, requests, rotation, center, semi_axes)
    return SynthesizedBatch(
        reference.topology,
        requests,
        rotation,
        center,
        semi_axes,
        measured,
        factors,
        converged,
        mode,
        reference.name,
        fractions,
        joints,
    )


def synthesize(reference, request, options=None, **fields):
    """One mannequin from a request (dict or 5 numbers, cm), named ``options.name`` (default: from the request).
    ``options`` and keywords as :func:`synthesize_batch`'s. Returns (Mannequin, measured dict, warnings)."""
    options = options_of(options, **fields).checked()
    values, warnings = checked_request(request, reference.ranges, reference.absurd_limits)
    batch = synthesize_checked(reference, values[None], options)
    if not batch.converged[0]:
        worst = MEASUREMENTS[int(np.argmax(batch.relative_error()[0]))]
        warnings.append(f"exact mode did not fully converge: {worst} is off by {batch.relative_error()[0].max():.2f}%")
    return batch.mannequin(0, options.name), as_dict(batch.measured[0]), warnings


class Synthesized(NamedTuple):
    """One mannequin as :func:`synthesize_extra` gives it."""

    mannequin: Mannequin
    measured: dict  # {the five and the six extra measurements: cm}, what the mannequin measures (the five alone
    # when none was given and measure_extra is False)
    warnings: list  # lines to show: requests outside the reference range, what exact mode missed (one line)
    missed: list  # what exact mode missed, as data (core.synthesis.misses.Miss); empty in IDW, which promises none


IDW_EXTRA_NOTE = "the extra measurements are met in exact mode only (IDW gives the reference set's)"


def synthesize_extra(reference, request, extra, options=None, measure_extra=True):
    """One mannequin meeting the five of ``request`` (dict or 5 values, cm) and the given ``extra`` measurements
    ({key: cm}; exact mode; IDW leaves the extra ones as the reference set gives them): a :class:`Synthesized`.
    The request is checked here, once (MeasurementError naming the field); ExtraRequestError for extra ones out
    of their limits or contradicting the five. ``measure_extra=False``: with no ``extra`` given, the five alone are
    measured (the six cost more than an exact synthesis; the panel and ``synth`` show no others)."""
    options = options_of(options).checked()
    values, warnings = checked_request(request, reference.ranges, reference.absurd_limits)
    problems = extra_request_problems(as_dict(values), extra)
    if problems:
        raise ExtraRequestError(problems[0])
    batch = synthesize_checked(reference, values[None], options)
    mannequin, measured, note = meet_extra_request(
        batch.mannequin(0, options.name), as_dict(batch.measured[0]), extra, options.mode, measure_extra
    )
    missed = request_misses(measured, values, extra, options.mode)
    warnings += ([note] if note else []) + ([missed_text(missed)] if missed else [])
    return Synthesized(mannequin, measured, warnings, missed)


def meet_extra_request(mannequin, measured, extra, mode, measure_extra=True):
    """The extra measurements of a synthesized ``mannequin`` (m_T ``measured`` {the five: cm}): in exact mode, the
    ``extra`` ones given met (``meet_extra``); otherwise (or with none given) as the reference set gives them.
    Returns (mannequin, measured {the five and the six: cm}, a note for the user or None). What ``synth``, the
    panel and each row of ``batch`` run (core.synthesis.batch.synthesize_chunk). ``measure_extra=False``: with
    none given, ``measured`` as it is (the five)."""
    if extra and mode == "exact":
        mannequin, measured, _ = meet_extra(mannequin, extra)  # its misses: judged by request_misses, as for all
        return mannequin, measured, None
    if not (extra or measure_extra):
        return mannequin, measured, None
    return mannequin, dict(measured, **mannequin_extra_measurements(mannequin)), IDW_EXTRA_NOTE if extra else None
