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
``"height"`` scales heights only. At an RM's measurements the scales cancel and the result is the RM;
the weights are the paper's; what is bounded by the RMs is the proportions, not the geometry itself
(a request outside L is scaled beyond the RMs).

**Exact mode** (beyond the paper): IDW is a weighted mean, so m_T of its result misses the request
(the paper's by a few percent, Table 2.4; proportional IDW by less). ``refine`` then deforms the
mannequin gently until m_T matches: five factors, solved by quasi-Newton steps on log m_T (starting
from the RMs' mean Jacobian, Broyden updates):

- He: vertical stretch about the floor (centres' z, and each semi-axis by its vertical share);
- Br, Wa, Hi: horizontal scaling of the girth ellipsoids about the body's vertical axis, blended
  with height by hat functions peaking at each section, so neighbouring parts move together;
- Sh: the shoulder ellipsoids (those that depend on Sh) widen along x; the arms hanging from them
  (non-girth parts that depend on Sh) are carried sideways by the same amount, not thickened.

Rotations are never changed by the refinement; every operation is symmetric about x = 0.
"""

import math
import os
import pathlib
from dataclasses import dataclass, fields

import numpy as np

from .clean import asymmetry
from .constants import (
    ABSURD_LIMITS,
    CENTER_LIMIT,
    CM_PER_M,
    GIRTHS,
    MEASUREMENTS,
    RANGES,
    REFERENCE_MEASUREMENTS,
    SECTION_FRACTIONS,
    SEMI_AXIS_LIMITS,
)
from .ellipsoid import axis_extent, section_at_height
from .errors import ElliMannError, MannequinError, MeasurementError, ReferenceSetError
from .frames import SAGITTAL_REFLECTION, rotation_mean, symmetrize_central
from .mannequin import Mannequin
from .measure import as_dict, section_heights, tailor_measurements

REFERENCE_NAMES = tuple(REFERENCE_MEASUREMENTS)  # small_slim, tall_slim, small_chubby, tall_chubby, average
REFERENCE_FOLDER = pathlib.Path(__file__).resolve().parents[2] / "reference_blends"
METRICS = ("raw", "normalized")
MODES = ("idw", "exact")
# What IDW averages: the RMs' geometry (the paper), or their proportions ("Proportional IDW" above).
NORMALIZATIONS = ("none", "height", "proportional")
PAPER_NORMALIZE = "none"
DEFAULT_NORMALIZE = "proportional"
DEFAULT_POWER = 2.0
POWER_LIMITS = (0.5, 16.0)
ZERO_DISTANCE = 1e-9  # closer than this (cm, or range units) is the RM's own point
SYMMETRY_TOLERANCE = 1e-6  # m: RMs must be symmetric to this for the mirrored synthesis to be exact

# Exact mode.
EXACT_TOLERANCE = 1e-5  # relative m_T error at which refinement stops (0.001 %)
EXACT_MAX_ITERATIONS = 12
_JACOBIAN_REFRESH = 4  # Broyden steps before a slow mannequin gets a fresh finite-difference Jacobian
FACTOR_LIMITS = (0.75, 4.0 / 3.0)  # the refinement never scales beyond these (it would show)
_MAX_STEP = 0.1  # largest change of a log factor per Newton step
_FD_STEP = 1e-4  # log-factor step of the finite-difference Jacobian
_TIKHONOV = 1e-10  # keeps the Newton system solvable when a measurement does not respond
_TAPER = 1.0  # how strongly a section's factor lengthens the parts it cuts off their middle
_DAMPING = 1e-3  # initial Levenberg-Marquardt damping (relative to each factor's own curvature)
# Hat functions of the girth blend, in fractions of He: full effect at a section, none beyond the
# neighbouring knots. Below the hip section the blend fades over the thighs, above the breast over
# the upper chest (as far above Br as Wa is below it).
_KNOTS = (
    SECTION_FRACTIONS["Hi"] - (SECTION_FRACTIONS["Wa"] - SECTION_FRACTIONS["Hi"]),
    SECTION_FRACTIONS["Hi"],
    SECTION_FRACTIONS["Wa"],
    SECTION_FRACTIONS["Br"],
    SECTION_FRACTIONS["Br"] + (SECTION_FRACTIONS["Br"] - SECTION_FRACTIONS["Wa"]),
)
_GIRTH_KNOT = {"Hi": 1, "Wa": 2, "Br": 3}
_INDEX = {key: i for i, key in enumerate(MEASUREMENTS)}


# --------------------------------------------------------------------------------------------
# Requests


def _number(value):
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def validate_request(me):
    """Check a request {He, Sh, Br, Wa, Hi} in cm (a dict, or a sequence in that order).

    Raises MeasurementError naming the field for a missing key, a non-number, NaN/inf, a value
    <= 0 or outside ``ABSURD_LIMITS``. Returns a list of warnings for values outside the
    reference range L (allowed: exact mode reaches them, IDW cannot leave the RMs' hull).
    """
    values = _request_values(me)
    warnings = []
    for key, value in zip(MEASUREMENTS, values):
        low, high = ABSURD_LIMITS[key]
        accepted = f"accepted range {low:g}-{high:g} cm"
        if not _number(value):
            raise MeasurementError(key, f"must be a number in cm, got {value!r} ({accepted})")
        if not math.isfinite(value):
            raise MeasurementError(key, f"must be a finite number, got {value!r} ({accepted})")
        if value <= 0:
            raise MeasurementError(key, f"must be > 0, got {value:g} ({accepted})")
        if not low <= value <= high:
            raise MeasurementError(key, f"{value:g} cm is not a plausible value ({accepted})")
        lo, hi = RANGES[key]
        if value < lo or value > hi:
            bound = lo if value < lo else hi
            by = abs(value - bound)
            warnings.append(f"{key} = {value:g} cm is outside the reference range {lo:g}-{hi:g} cm by {by:.4g} cm "
                            f"({100.0 * by / bound:.1f}%): the paper's IDW stays inside the range, proportional "
                            "IDW and exact mode extrapolate")
    return warnings


def _request_values(me):
    if isinstance(me, dict):
        missing = [key for key in MEASUREMENTS if key not in me]
        if missing:
            raise MeasurementError(missing[0], f"is missing; a request needs {', '.join(MEASUREMENTS)} in cm")
        unknown = [key for key in me if key not in MEASUREMENTS]
        if unknown:
            raise MeasurementError(str(unknown[0]), f"is not a measurement; expected {', '.join(MEASUREMENTS)}")
        return [me[key] for key in MEASUREMENTS]
    if isinstance(me, str):
        raise MeasurementError("request", "must be a dict or 5 numbers He, Sh, Br, Wa, Hi (cm)")
    try:
        values = list(me)
    except TypeError:
        raise MeasurementError("request", "must be a dict or 5 numbers He, Sh, Br, Wa, Hi (cm)") from None
    if len(values) != len(MEASUREMENTS):
        field = MEASUREMENTS[len(values)] if len(values) < len(MEASUREMENTS) else "request"
        raise MeasurementError(field, f"a request needs 5 values He, Sh, Br, Wa, Hi (cm), got {len(values)}")
    return values


def request_array(me):
    """Validated request as a (5,) float array (warnings dropped; use validate_request to see them)."""
    validate_request(me)
    return np.array(_request_values(me), dtype=float)


def mannequin_name(me):
    """'ElliMann 159-43-117-104-117': the name of a synthesized mannequin, from its request."""
    values = request_array(me)
    return "ElliMann " + "-".join(f"{v:.6g}" for v in values)


def relative_error(measured, requested, signed=False):
    """Relative error of m_T against the request, in %: 100 |measured - requested| / requested.

    Arrays (..., 5) in the order of MEASUREMENTS, or dicts keyed by them (then a (5,) array).
    ``signed``: 100 (measured - requested) / requested instead (positive when m_T is larger).
    The one formula every report, panel and table uses.
    """
    measured, requested = (np.asarray([v[k] for k in MEASUREMENTS] if isinstance(v, dict) else v, dtype=float)
                           for v in (measured, requested))
    error = 100.0 * (measured - requested) / requested
    return error if signed else np.abs(error)


def check_options(mode="idw", metric="raw", power=DEFAULT_POWER, normalize=DEFAULT_NORMALIZE):
    if mode not in MODES:
        raise ElliMannError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    if normalize not in NORMALIZATIONS:
        raise ElliMannError(f"normalize must be one of {', '.join(NORMALIZATIONS)}, got {normalize!r}")
    if metric not in METRICS:
        raise ElliMannError(f"metric must be one of {', '.join(METRICS)}, got {metric!r}")
    if not _number(power) or not POWER_LIMITS[0] <= power <= POWER_LIMITS[1]:
        raise ElliMannError(f"power p must be a number in {POWER_LIMITS[0]:g}-{POWER_LIMITS[1]:g}, got {power!r}")


# --------------------------------------------------------------------------------------------
# Reference set


class ReferenceSet:
    """The Reference Mannequins: one topology, geometry stacks (k, n, ...) and measurements (k, 5) cm.

    ``measurements`` are the RMs' nominal measurements (Table 2.3), the points Eq. 2.1 interpolates
    between. Every RM is reordered to the first one's topology.
    """

    def __init__(self, mannequins, names=None, sources=None):
        mannequins = list(mannequins)
        names = list(names or [m.name or f"RM {i + 1}" for i, m in enumerate(mannequins)])
        sources = list(sources or names)
        if len(mannequins) < 2:
            raise ReferenceSetError("", "reference set", f"needs at least 2 mannequins, got {len(mannequins)}")
        first = mannequins[0]
        ordered, measurements = [], []
        for mannequin, source in zip(mannequins, sources):
            problems = mannequin.problems()
            if problems:
                raise ReferenceSetError(source, "geometry", str(MannequinError(problems)))
            mismatch = first.topology.mismatch(mannequin.topology)
            if mismatch:
                more = f" (and {len(mismatch) - 1} more)" if len(mismatch) > 1 else ""
                raise ReferenceSetError(source, "topology", f"differs from {sources[0]}: {mismatch[0]}{more}")
            mannequin = mannequin.reordered(first.topology) if mannequin.topology != first.topology else mannequin
            ordered.append(mannequin)
            measurements.append(_reference_measurements(mannequin, source))
            off = asymmetry(mannequin)
            if off > SYMMETRY_TOLERANCE:
                raise ReferenceSetError(source, "geometry", f"is not symmetric about x = 0 (asymmetry "
                                        f"{off * 1e3:.3g} mm); clean it first")
        self.mannequins = ordered
        self.names = names
        self.sources = sources
        self.topology = first.topology
        self.measurements = np.array(measurements)
        self.mirror_label_mismatch = []  # right parts whose axis labels differ between RMs
        self.rotation = np.stack([m.rotation for m in ordered])
        self.center = np.stack([m.center for m in ordered])
        self.semi_axes = np.stack([m.semi_axes for m in ordered])
        for j in range(len(ordered)):
            for i in range(j):
                if np.allclose(self.measurements[i], self.measurements[j]):
                    raise ReferenceSetError(sources[j], "measurements_cm", f"are the same as those of {sources[i]}; "
                                            "IDW needs distinct reference points")
        topology = self.topology
        self._left = topology.indices("L")
        self._right = topology.twin_indices[self._left]
        self._central = topology.indices("C")
        self._source = np.concatenate([self._left, self._central]).astype(int)
        self._mirror_signs = self._find_mirror_signs()
        mask = topology.dependency_mask[self._source].astype(float)  # (s, 5)
        self._mask = mask
        # coincide[s, j, l]: RMs j and l have the same measurements in part s's sub-space.
        diff = np.abs(self.measurements[:, None, :] - self.measurements[None, :, :])  # (k, k, 5)
        self._coincide = np.all((diff[None] <= ZERO_DISTANCE) | (mask[:, None, None, :] == 0.0), axis=-1)
        # Proportional IDW: a part's heights go with He, its widths with the geometric mean of the
        # other measurements it depends on (one for every part of the shipped topology); only with
        # measurements it depends on, so it stays a function of its own sub-space.
        he = _INDEX["He"]
        self._height_exponent = np.zeros_like(mask)
        self._height_exponent[:, he] = mask[:, he]
        widths = mask.copy()
        widths[:, he] = 0.0
        self._width_exponent = widths / np.maximum(widths.sum(axis=1, keepdims=True), 1.0)
        self._size_origin = self.measurements.mean(axis=0)  # scales are relative to the RMs' mean
        self._normalized = {}
        self._jacobian = None

    def __len__(self):
        return len(self.mannequins)

    def size_scales(self, measurements, normalize):
        """Horizontal and vertical scale (..., s) of each interpolated part at ``measurements`` (..., 5) cm.

        1 at the mean of the RMs' measurements; ones throughout for ``normalize="none"``.
        """
        log = np.log(np.asarray(measurements, dtype=float) / self._size_origin)
        ones = np.ones(log.shape[:-1] + (len(self._source),))
        if normalize == "none":
            return ones, ones
        vertical = np.exp(log @ self._height_exponent.T)
        horizontal = np.exp(log @ self._width_exponent.T) if normalize == "proportional" else ones
        return horizontal, vertical

    def refine_jacobian(self):
        """(5, 5) d log m_T / d log factor of the refinement, the mean over the RMs (computed once).

        Exact mode starts its Broyden updates from it instead of five m_T per mannequin: the
        deformation acts alike on every body (its entries vary by a few hundredths between the RMs).
        """
        if self._jacobian is None:
            girth = self.topology.girth_mask
            measured = tailor_measurements(self.rotation, self.center, self.semi_axes, girth)
            basis = _deform_basis(self.topology, self.rotation, self.center, self.semi_axes, measured)
            each = _fd_jacobian(basis, np.arange(len(self)), self.rotation, self.center, self.semi_axes,
                                np.zeros((len(self), len(MEASUREMENTS))), np.log(measured), girth)
            self._jacobian = each.mean(axis=0)
        return self._jacobian

    def normalized_geometry(self, normalize):
        """The RMs' centres and semi-axes (k, s, 3) of the interpolated parts, divided by their own scales."""
        if normalize not in self._normalized:
            src = self._source
            horizontal, vertical = self.size_scales(self.measurements, normalize)
            center = self.center[:, src] / _center_scale(horizontal, vertical)
            semi_axes = self.semi_axes[:, src] / _axis_scale(self.rotation[:, src], horizontal, vertical)
            self._normalized[normalize] = (center, semi_axes)
        return self._normalized[normalize]

    def _find_mirror_signs(self):
        """Per left part, the axis signs that turn its sagittal reflection into the right twin's frame.

        Taken from the RMs (after ``clean.clean`` they all agree). Where they do not, the pattern most
        RMs use wins: the right ellipsoid is the same set either way, only its axis labels differ.
        """
        if not len(self._left):
            return np.ones((0, 3))
        reflected = SAGITTAL_REFLECTION @ self.rotation[:, self._left]  # (k, l, 3, 3)
        agreement = np.swapaxes(reflected, -1, -2) @ self.rotation[:, self._right]  # diag(signs) if mirrored
        signs = np.where(np.diagonal(agreement, axis1=-2, axis2=-1) >= 0.0, 1.0, -1.0)  # (k, l, 3)
        mirrored = np.abs(agreement - signs[..., None] * np.eye(3)).max(axis=(-1, -2)) <= 1e-6  # (k, l)
        chosen = np.empty((len(self._left), 3))
        self.mirror_label_mismatch = []
        for p in range(len(self._left)):
            patterns = [tuple(signs[j, p]) for j in range(len(self)) if mirrored[j, p]]
            if len(set(patterns)) != 1 or len(patterns) != len(self):
                self.mirror_label_mismatch.append(self.topology.names[self._right[p]])
            chosen[p] = max(patterns, key=patterns.count) if patterns else (-1.0, 1.0, 1.0)
        return chosen

def _reference_measurements(mannequin, source):
    me = mannequin.measurements
    if not isinstance(me, dict):
        raise ReferenceSetError(source, "measurements_cm", "is missing: a Reference Mannequin needs its He, Sh, Br, "
                                "Wa, Hi (cm)")
    values = []
    for key in MEASUREMENTS:
        value = me.get(key)
        if value is None:
            raise ReferenceSetError(source, f"measurements_cm.{key}", "is missing")
        if not _number(value) or not math.isfinite(value) or value <= 0:
            raise ReferenceSetError(source, f"measurements_cm.{key}",
                                    f"must be a positive finite number, got {value!r}")
        values.append(float(value))
    return values


def load_reference_set(folder=None, names=REFERENCE_NAMES):
    """The five RMs from ``folder`` (default: the shipped ``reference_blends/``), one JSON file each."""
    folder = pathlib.Path(folder) if folder is not None else REFERENCE_FOLDER
    if folder.exists() and not folder.is_dir():
        raise ReferenceSetError(str(folder), "path", f"is a file, not a folder (a reference set is the folder "
                                f"holding {', '.join(f'{n}.json' for n in names)})")
    if not folder.is_dir():
        raise ReferenceSetError(str(folder), "folder", "does not exist")
    mannequins, sources = [], []
    for name in names:
        path = folder / f"{name}.json"
        if not path.is_file():
            raise ReferenceSetError(str(path), "file", f"is missing (a reference set needs {', '.join(names)} .json)")
        try:
            mannequins.append(Mannequin.load(path))
        except (MannequinError, OSError, UnicodeDecodeError) as error:
            raise ReferenceSetError(str(path), "file", f"cannot be read: {error}") from None
        sources.append(str(path))
    return ReferenceSet(mannequins, names=list(names), sources=sources)


_CACHE = {}


def cached_reference_set(folder=None):
    """load_reference_set, memoised on the files' modification times (for the live panel and batches)."""
    folder = pathlib.Path(folder) if folder else REFERENCE_FOLDER
    try:
        stamp = tuple(os.stat(folder / f"{n}.json").st_mtime_ns for n in REFERENCE_NAMES)
    except OSError:
        stamp = None
    key = str(folder.resolve())
    hit = _CACHE.get(key)
    if stamp is not None and hit is not None and hit[0] == stamp:
        return hit[1]
    reference = load_reference_set(folder)
    _CACHE[key] = (stamp, reference)
    return reference


# --------------------------------------------------------------------------------------------
# Segmented IDW


def _metric_scale(metric):
    if metric == "raw":
        return np.ones(len(MEASUREMENTS))
    return np.array([RANGES[key][1] - RANGES[key][0] for key in MEASUREMENTS])


def _inverse_distance(distance, power):
    """IDW weights along the last axis; a zero distance takes all the weight (shared if several)."""
    zero = distance <= ZERO_DISTANCE
    nearest = np.where(zero, np.inf, distance).min(axis=-1, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        # (d_min / d)^p <= 1: no overflow for tiny distances or large p.
        relative = np.where(zero, 0.0, (nearest / np.where(zero, 1.0, distance)) ** power)
    weights = np.where(zero.any(axis=-1, keepdims=True), zero.astype(float), relative)
    return weights / weights.sum(axis=-1, keepdims=True)


def idw_weights(reference, requests, metric="raw", power=DEFAULT_POWER):
    """Weights (B, s, k) of the k RMs for each interpolated part s (left and central) of each request.

    Non-negative, summing to 1 over k. See the module docstring for parts whose sub-space
    does not separate some RMs.
    """
    requests = np.atleast_2d(np.asarray(requests, dtype=float))
    diff = (requests[:, None, :] - reference.measurements[None]) / _metric_scale(metric)  # (B, k, 5)
    sub = np.sqrt(np.einsum("bkm,sm->bsk", diff * diff, reference._mask))
    full = np.sqrt(np.sum(diff * diff, axis=-1))
    w_sub = _inverse_distance(sub, power)  # (B, s, k)
    w_full = _inverse_distance(full, power)  # (B, k)
    coincide = reference._coincide.astype(float)  # (s, k, k)
    group_full = np.einsum("sjl,bl->bsj", coincide, w_full)
    group_size = coincide.sum(axis=-1)  # (s, k)
    share = np.divide(group_size * w_full[:, None, :], group_full, out=np.ones_like(group_full),
                      where=group_full > 0.0)
    weights = w_sub * share
    return weights / weights.sum(axis=-1, keepdims=True)


def _center_scale(horizontal, vertical):
    """(..., 3) scale of a centre: x and y (about the registration origin) by the width, z (about the floor)
    by the height."""
    return np.stack([horizontal, horizontal, vertical], axis=-1)


def _axis_scale(rotation, horizontal, vertical):
    """(..., 3) scale of each semi-axis: vertical^v * horizontal^(1 - v), v = the axis' share along world z.

    The rotation is kept; for an upright ellipsoid (one axis along z) this is exactly the ellipsoid
    scaled by diag(horizontal, horizontal, vertical).
    """
    v = rotation[..., 2, :] ** 2
    return vertical[..., None] ** v * horizontal[..., None] ** (1.0 - v)


def interpolate(reference, requests, metric="raw", power=DEFAULT_POWER, normalize=DEFAULT_NORMALIZE):
    """Segmented IDW for a batch (B, 5) cm -> rotation (B, n, 3, 3), center (B, n, 3), semi_axes (B, n, 3).

    ``normalize="none"`` is the paper's Eq. 2.1 on the RMs' geometry; "height" and "proportional"
    average the geometry divided by each RM's scales and multiply the mean by the request's
    (module docstring). Rotations and weights are the same in all three.
    """
    requests = np.atleast_2d(np.asarray(requests, dtype=float))
    weights = idw_weights(reference, requests, metric, power)  # (B, s, k)
    src = reference._source
    batch, n = requests.shape[0], len(reference.topology)
    rotation = np.empty((batch, n, 3, 3))
    center = np.empty((batch, n, 3))
    semi_axes = np.empty((batch, n, 3))
    # rotation_mean takes the k items on axis 0: rotations (k, 1, s, 3, 3), weights (k, B, s).
    rotation[:, src] = rotation_mean(reference.rotation[:, None, src], np.moveaxis(weights, -1, 0))
    if normalize == "none":
        center[:, src] = np.einsum("bsk,ksi->bsi", weights, reference.center[:, src])
        semi_axes[:, src] = np.einsum("bsk,ksi->bsi", weights, reference.semi_axes[:, src])
    else:
        ref_center, ref_semi = reference.normalized_geometry(normalize)
        horizontal, vertical = reference.size_scales(requests, normalize)  # (B, s)
        center[:, src] = np.einsum("bsk,ksi->bsi", weights, ref_center) * _center_scale(horizontal, vertical)
        semi_axes[:, src] = (np.einsum("bsk,ksi->bsi", weights, ref_semi)
                             * _axis_scale(rotation[:, src], horizontal, vertical))
    central, left, right = reference._central, reference._left, reference._right
    if len(central):
        rotation[:, central], center[:, central] = symmetrize_central(rotation[:, central], center[:, central])
    if len(left):
        rotation[:, right] = (SAGITTAL_REFLECTION @ rotation[:, left]) * reference._mirror_signs[:, None, :]
        center[:, right] = center[:, left] * np.array([-1.0, 1.0, 1.0])
        semi_axes[:, right] = semi_axes[:, left]
    return rotation, center, semi_axes


# --------------------------------------------------------------------------------------------
# Exact refinement


@dataclass
class _DeformBasis:
    """What the deformation needs from the unrefined geometry (held fixed while factors change)."""

    bottom: np.ndarray  # (B,) m
    shoulder_half: np.ndarray  # (B,) m, half of Sh
    girth_weight: np.ndarray  # (B, n, 3) hat weight of each part for Br, Wa, Hi (GIRTHS order)
    origin_y: np.ndarray  # (B, n) y of the vertical axis the girth scaling is about, at each part
    vertical: np.ndarray  # (B, n, 3) share of each local axis along world z (R[2, k]^2)
    lateral: np.ndarray  # (B, n, 3) share along world x
    taper: np.ndarray  # (B, n, 3) how far off its middle each girth part is cut by Br, Wa, Hi (0..1)
    anchor: np.ndarray  # (B, n, 3) z of the end of the part farther from each section
    shoulder_scaled: np.ndarray  # (n,) parts that widen with Sh
    shoulder_carried: np.ndarray  # (n,) parts moved sideways with Sh (arms)

    _SHARED = ("shoulder_scaled", "shoulder_carried")  # per part, not per mannequin

    def take(self, rows):
        return _DeformBasis(**{f.name: getattr(self, f.name) if f.name in self._SHARED else getattr(self, f.name)[rows]
                               for f in fields(self)})

    def tile(self, count):
        def rep(a):
            return np.tile(a, (count,) + (1,) * (a.ndim - 1))

        return _DeformBasis(**{f.name: getattr(self, f.name) if f.name in self._SHARED else rep(getattr(self, f.name))
                               for f in fields(self)})


def _hat(fraction, knot):
    """Piecewise-linear hat over _KNOTS, 1 at _KNOTS[knot], 0 at its neighbours and beyond."""
    return np.interp(fraction, _KNOTS, np.eye(len(_KNOTS))[knot])


# Points across an ellipsoid's height (in half-extents) and their weights, proportional to the area
# of the horizontal section there (1 - t^2): the blend weight of a part is the hat averaged over it.
_SPAN = np.linspace(-1.0, 1.0, 9)[1:-1]
_SPAN_WEIGHT = (1.0 - _SPAN**2) / np.sum(1.0 - _SPAN**2)


def _deform_basis(topology, rotation, center, semi_axes, measured):
    bottom, height, z = section_heights(rotation, center, semi_axes)
    span = center[..., 2, None] + axis_extent(rotation, semi_axes, 2)[..., None] * _SPAN  # (B, n, q)
    fraction = (span - bottom[:, None, None]) / height[:, None, None]
    girth = topology.girth_mask
    weight = np.stack([_hat(fraction, _GIRTH_KNOT[key]) @ _SPAN_WEIGHT for key in GIRTHS], axis=-1)
    weight = weight * girth[:, None]
    fraction = (center[..., 2] - bottom[:, None]) / height[:, None]
    # Each girth section's own centre in y (middle of its extent), interpolated between sections.
    centre_y = []
    for key in GIRTHS:
        c2, k2, hit = section_at_height(rotation, center, semi_axes, z[key][:, None])
        active = hit & girth
        half = np.sqrt(k2[..., 1, 1])
        top = np.where(active, c2[..., 1] + half, -np.inf).max(axis=-1)
        low = np.where(active, c2[..., 1] - half, np.inf).min(axis=-1)
        centre_y.append(np.where(np.isfinite(top), 0.5 * (top + low), 0.0))
    centre_y = np.stack(centre_y, axis=-1)  # (B, 3) in GIRTHS order: Br, Wa, Hi
    order = [GIRTHS.index(key) for key in ("Hi", "Wa", "Br")]
    fractions = [SECTION_FRACTIONS[key] for key in ("Hi", "Wa", "Br")]
    origin_y = np.stack([np.interp(fraction[b], fractions, centre_y[b, order]) for b in range(len(bottom))])
    # Where each section cuts each girth part, relative to the part's middle (-1 bottom .. 1 top).
    half_z = axis_extent(rotation, semi_axes, 2)  # (B, n)
    cut = np.stack([(z[key][:, None] - center[..., 2]) / half_z for key in GIRTHS], axis=-1)  # (B, n, 3)
    crossing = (np.abs(cut) < 1.0) & girth[:, None]
    taper = np.where(crossing, np.abs(cut), 0.0)
    anchor = center[..., 2, None] - np.sign(cut) * half_z[..., None]
    depends_sh = topology.dependency_mask[:, _INDEX["Sh"]]
    return _DeformBasis(
        bottom=bottom, shoulder_half=0.5 * measured[:, _INDEX["Sh"]] / CM_PER_M, girth_weight=weight,
        origin_y=origin_y, vertical=rotation[..., 2, :] ** 2, lateral=rotation[..., 0, :] ** 2,
        taper=taper, anchor=anchor, shoulder_scaled=depends_sh & girth, shoulder_carried=depends_sh & ~girth)


def deform(basis, center, semi_axes, factors):
    """Apply refinement factors (B, 5) (He, Sh, Br, Wa, Hi; 1 = unchanged) -> (center, semi_axes).

    Rotations are unchanged. Symmetric about x = 0 by construction.
    """
    f = np.asarray(factors, dtype=float)
    center = center.copy()
    semi = semi_axes.copy()
    girth_f = f[:, [_INDEX[key] for key in GIRTHS]]  # (B, 3)
    # Br, Wa, Hi, first: a part cut by a section away from its middle is lengthened or shortened
    # from its far end, which widens or narrows it there much more than in its middle (a rib cage
    # ending higher narrows the waist, not the bust).
    for g in range(len(GIRTHS)):
        v = girth_f[:, g, None] ** (_TAPER * basis.taper[..., g])  # (B, n)
        anchor = basis.anchor[..., g]
        center[..., 2] = anchor + v * (center[..., 2] - anchor)
        semi *= 1.0 + (v[..., None] - 1.0) * basis.vertical
    # He: vertical stretch about the floor.
    he = f[:, _INDEX["He"], None]
    center[..., 2] = basis.bottom[:, None] + he * (center[..., 2] - basis.bottom[:, None])
    semi *= 1.0 + (he[..., None] - 1.0) * basis.vertical
    # Br, Wa, Hi: horizontal scaling blended with height.
    sigma = 1.0 + np.einsum("bng,bg->bn", basis.girth_weight, girth_f - 1.0)
    center[..., 0] *= sigma
    center[..., 1] = basis.origin_y + sigma * (center[..., 1] - basis.origin_y)
    semi *= 1.0 + (sigma[..., None] - 1.0) * (1.0 - basis.vertical)
    # Sh: the shoulders widen along x; the arms hanging from them move out with their edge.
    sh = f[:, _INDEX["Sh"], None]
    scaled = basis.shoulder_scaled[None, :]
    center[..., 0] = np.where(scaled, center[..., 0] * sh, center[..., 0])
    semi = np.where(scaled[..., None], semi * (1.0 + (sh[..., None] - 1.0) * basis.lateral), semi)
    shift = np.sign(center[..., 0]) * (sh - 1.0) * basis.shoulder_half[:, None]
    center[..., 0] += np.where(basis.shoulder_carried[None, :], shift, 0.0)
    return center, semi


@dataclass
class Refinement:
    center: np.ndarray
    semi_axes: np.ndarray
    measured: np.ndarray  # (B, 5) cm, m_T of the refined mannequins
    factors: np.ndarray  # (B, 5) the deformation factors found (1 = unchanged)
    iterations: int
    converged: np.ndarray  # (B,) bool: every measurement within the tolerance


def refine(topology, rotation, center, semi_axes, targets, measured=None, tolerance=EXACT_TOLERANCE,
           max_iterations=EXACT_MAX_ITERATIONS, jacobian=None):
    """Deform mannequins (B, n, ...) so that m_T matches ``targets`` (B, 5) cm (exact mode).

    Solves r(x) = log m_T(deform(exp x)) - log target = 0 for the log factors x, Levenberg-Marquardt
    style: starting from ``jacobian`` ((5, 5) or (B, 5, 5), e.g. ``ReferenceSet.refine_jacobian``)
    or, without one, a forward-difference Jacobian (5 m_T per mannequin); Broyden updates after
    every step (one m_T each), a step kept only if it lowers |r| (else more damping), a
    forward-difference Jacobian if a mannequin is slow to converge. The result is never further from
    the request than the IDW mannequin it starts from. All batched; mannequins already within
    ``tolerance`` are returned unchanged.
    """
    girth = topology.girth_mask
    targets = np.atleast_2d(np.asarray(targets, dtype=float))
    if measured is None:
        measured = tailor_measurements(rotation, center, semi_axes, girth)
    basis = _deform_basis(topology, rotation, center, semi_axes, measured)
    count = len(MEASUREMENTS)
    x = np.zeros((len(targets), count))
    current = measured.copy()
    residual = np.log(np.maximum(current, 1e-12) / targets)
    if jacobian is None:
        jacobian = np.zeros((len(targets), count, count))
        age = np.full(len(targets), -1)  # steps since the Jacobian was computed (-1: never)
    else:
        jacobian = np.broadcast_to(np.asarray(jacobian, dtype=float), (len(targets), count, count)).copy()
        age = np.zeros(len(targets), dtype=int)
    damping = np.full(len(targets), _DAMPING)
    # A factor that reaches FACTOR_LIMITS is frozen there and its measurement left as close as that
    # allows; the other factors keep solving their own measurements (no trading one for another).
    free = np.ones((len(targets), count), dtype=bool)
    out_center, out_semi = center.copy(), semi_axes.copy()
    lo, hi = np.log(FACTOR_LIMITS)
    eye = np.eye(count)
    iterations = 0
    for _ in range(max_iterations):
        todo = np.nonzero((np.abs(residual) * free).max(axis=1) > tolerance)[0]
        if not len(todo):
            break
        iterations += 1
        stale = todo[(age[todo] < 0) | (age[todo] >= _JACOBIAN_REFRESH)]
        if len(stale):
            jacobian[stale] = _fd_jacobian(basis, rows=stale, rotation=rotation, center=center, semi_axes=semi_axes,
                                           x=x, base=np.log(np.maximum(current[stale], 1e-12)), girth=girth)
            age[stale] = 0
        j = jacobian[todo]
        mask = free[todo]
        reduced = j * mask[:, :, None] * mask[:, None, :]
        rt = np.swapaxes(reduced, -1, -2)
        normal = rt @ reduced
        scale = np.diagonal(normal, axis1=-2, axis2=-1) + _TIKHONOV  # Marquardt: each factor by its own scale
        system = normal + (damping[todo, None] * scale + ~mask)[..., None] * eye
        # A stacked right-hand side as explicit column vectors: numpy 2 no longer broadcasts (t, f) against (t, f, f).
        rhs = np.einsum("tfm,tm->tf", rt, residual[todo] * mask)
        step = -np.linalg.solve(system, rhs[..., None])[..., 0]
        wanted = x[todo] + np.clip(step, -_MAX_STEP, _MAX_STEP)
        new_x = np.clip(wanted, lo, hi)
        c, d = deform(basis.take(todo), center[todo], semi_axes[todo], np.exp(new_x))
        m = tailor_measurements(rotation[todo], c, d, girth)
        new_residual = np.log(np.maximum(m, 1e-12) / targets[todo])
        # Broyden: the secant of this step corrects the Jacobian along the step, kept or not.
        dx = new_x - x[todo]
        norm = np.einsum("tf,tf->t", dx, dx)
        miss = new_residual - residual[todo] - np.einsum("tmf,tf->tm", j, dx)
        jacobian[todo] = j + np.divide(miss[:, :, None] * dx[:, None, :], norm[:, None, None],
                                       out=np.zeros_like(j), where=norm[:, None, None] > 0)
        age[todo] += 1
        better = np.sum((new_residual * mask) ** 2, axis=1) < np.sum((residual[todo] * mask) ** 2, axis=1)
        damping[todo] = np.where(better, damping[todo] / 3.0, damping[todo] * 4.0)
        keep = todo[better]
        x[keep], residual[keep], current[keep] = new_x[better], new_residual[better], m[better]
        out_center[keep], out_semi[keep] = c[better], d[better]
        free[keep] &= new_x[better] == wanted[better]
    converged = np.abs(residual).max(axis=1) <= tolerance
    return Refinement(out_center, out_semi, current, np.exp(x), iterations, converged)


def _fd_jacobian(basis, rows, rotation, center, semi_axes, x, base, girth):
    """d log m_T / d log factor (T, measurement, factor) by forward differences at x[rows]."""
    count = len(MEASUREMENTS)
    probes = np.concatenate([x[rows] + _FD_STEP * np.eye(count)[j] for j in range(count)])
    c, d = deform(basis.take(rows).tile(count), np.tile(center[rows], (count, 1, 1)),
                  np.tile(semi_axes[rows], (count, 1, 1)), np.exp(probes))
    m = tailor_measurements(np.tile(rotation[rows], (count, 1, 1, 1)), c, d, girth)
    m = np.log(np.maximum(m, 1e-12)).reshape(count, len(rows), count)
    return np.moveaxis((m - base[None]) / _FD_STEP, 0, -1)


# --------------------------------------------------------------------------------------------
# Entry points


@dataclass
class Synthesis:
    """A batch of synthesized mannequins sharing the reference set's topology."""

    topology: object
    requests: np.ndarray  # (B, 5) cm
    rotation: np.ndarray  # (B, n, 3, 3)
    center: np.ndarray  # (B, n, 3)
    semi_axes: np.ndarray  # (B, n, 3)
    measured: np.ndarray  # (B, 5) cm, m_T of each result (None if not measured)
    factors: np.ndarray  # (B, 5) exact-mode deformation factors (ones for IDW)
    converged: np.ndarray  # (B,) exact mode reached its tolerance (True for IDW)
    mode: str

    def __len__(self):
        return len(self.requests)

    def mannequin(self, i, name=None):
        me = as_dict(self.requests[i])
        return Mannequin(self.topology, self.rotation[i], self.center[i], self.semi_axes[i],
                         name=name or mannequin_name(me), role="synthesized", measurements=me)

    def relative_error(self):
        """(B, 5) |m_T - request| / request in % (:func:`relative_error`)."""
        return relative_error(self.measured, self.requests)


def validate_requests(requests):
    """(B, 5) array check for batches; raises MeasurementError naming the row and field."""
    try:
        requests = np.atleast_2d(np.asarray(requests, dtype=float))
    except (TypeError, ValueError):
        raise MeasurementError("requests", "must be numbers (cm) in rows of He, Sh, Br, Wa, Hi") from None
    if requests.ndim != 2 or requests.shape[1] != len(MEASUREMENTS):
        raise MeasurementError("requests", f"must have shape (B, 5) (He, Sh, Br, Wa, Hi), got {requests.shape}")
    for row, values in enumerate(requests):
        try:
            validate_request([float(v) for v in values])
        except MeasurementError as error:
            raise MeasurementError(error.field, f"row {row}: {str(error).partition(': ')[2]}") from None
    return requests


def check_plausible(topology, requests, rotation, center, semi_axes):
    """Refuse synthesis results (B, n, ...) with a piece outside the plausibility limits (SEMI_AXIS_LIMITS,
    CENTER_LIMIT) or not finite, as a file or a collection holding them would be: ElliMannError naming the
    request, the part, the field and the range. One vectorised test; the message comes from
    ``Mannequin.problems`` of the first bad result."""
    low, high = SEMI_AXIS_LIMITS
    with np.errstate(invalid="ignore"):
        good = (np.all(np.isfinite(semi_axes), axis=-1) & np.all((semi_axes >= low) & (semi_axes <= high), axis=-1)
                & np.all(np.isfinite(center), axis=-1) & np.all(np.abs(center) <= CENTER_LIMIT, axis=-1)
                & np.all(np.isfinite(rotation), axis=(-1, -2)))
    if np.all(good):
        return
    row = int(np.argwhere(~good)[0][0])
    mannequin = Mannequin(topology, rotation[row], center[row], semi_axes[row])
    problems = [p for p in mannequin.problems() if p.field in ("rotation", "center", "semi_axes")]
    request = ", ".join(f"{k} {v:g}" for k, v in zip(MEASUREMENTS, requests[row]))
    raise ElliMannError(f"synthesis at {request} cm gives an implausible mannequin: {MannequinError(problems)}")


def synthesize_batch(reference, requests, mode="idw", metric="raw", power=DEFAULT_POWER, measure=True,
                     tolerance=EXACT_TOLERANCE, normalize=DEFAULT_NORMALIZE):
    """Synthesize many mannequins at once: requests (B, 5) cm -> Synthesis with (B, n, ...) arrays.

    The paper's method is ``mode="idw", normalize="none"`` (with the default raw metric and p = 2).
    """
    check_options(mode, metric, power, normalize)
    requests = validate_requests(requests)
    rotation, center, semi_axes = interpolate(reference, requests, metric, power, normalize)
    girth = reference.topology.girth_mask
    measured = tailor_measurements(rotation, center, semi_axes, girth) if (measure or mode == "exact") else None
    factors = np.ones_like(requests)
    converged = np.ones(len(requests), dtype=bool)
    if mode == "exact":
        result = refine(reference.topology, rotation, center, semi_axes, requests, measured, tolerance,
                        jacobian=reference.refine_jacobian())
        center, semi_axes, measured = result.center, result.semi_axes, result.measured
        factors, converged = result.factors, result.converged
    check_plausible(reference.topology, requests, rotation, center, semi_axes)
    return Synthesis(reference.topology, requests, rotation, center, semi_axes, measured, factors, converged, mode)


def synthesize(reference, request, mode="idw", metric="raw", power=DEFAULT_POWER, name=None,
               normalize=DEFAULT_NORMALIZE):
    """One mannequin from a request (dict or 5 numbers, cm). Returns (Mannequin, measured dict, warnings)."""
    warnings = validate_request(request)
    batch = synthesize_batch(reference, [request_array(request)], mode, metric, power, normalize=normalize)
    if not batch.converged[0]:
        worst = MEASUREMENTS[int(np.argmax(batch.relative_error()[0]))]
        warnings.append(f"exact mode did not fully converge: {worst} is off by {batch.relative_error()[0].max():.2f}%")
    return batch.mannequin(0, name), as_dict(batch.measured[0]), warnings
