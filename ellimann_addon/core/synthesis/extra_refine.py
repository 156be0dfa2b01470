"""Exact mode for the extra measurements: degrees of freedom of their own (a neck, the upper arms, the thighs, the
calves, the leg and arm lengths), alternated with the five's refinement (``core.synthesis.refine``) until every given
measurement is met.

Each extra measurement moves only its own pieces: a girth widens the section of the pieces it cuts (horizontal;
the upper arm's across the arm) as locally as ellipsoids allow, a piece cut off its middle lengthened from its
far end rather than scaled whole (``_widen_at``); the crotch height stretches the legs against the trunk; the
arm length stretches the arm along itself about the shoulder point. One log-factor per given
measurement, solved by secant steps per factor (each measurement responds almost only to its own factor),
with the five re-met by ``core.synthesis.refine.refine`` after every round (the extra factors nudge He and the girths).
"""

import numpy as np

from ..errors import ElliMannError
from ..geometry.ellipsoid import axis_extent, linear_image
from ..mannequin.joints import anchor_indices, follow_pieces
from ..measure.extra import (
    CALF_BAND,
    SIDES,
    THIGH_DROP,
    UPPER_ARM_FRACTION,
    MannequinLandmarks,
    mannequin_extra_measurements,
    neck_plane,
)
from ..measure.tailor import tailor_measurements
from ..measurements import EXTRA_ABSURD_LIMITS, EXTRA_GIRTHS, EXTRA_MEASUREMENTS, MEASUREMENT_LABELS, MEASUREMENTS
from .misses import MISS_CM, Miss
from .refine import refine

EXTRA_TOLERANCE_CM = 0.01  # every given extra measurement within 0.1 mm
EXTRA_MAX_ROUNDS = 12
FIVE_TOLERANCE_CM = 0.01  # a round that moves any of the five further than this is never the result
EXTRA_FACTOR_LIMIT = 2.0  # no piece scaled beyond this or below its inverse (it would no longer look like itself)
_MAX_LOG_STEP = 0.25
# How much of a girth's factor lengthens a piece cut off its middle (times |cut|), per measurement: measured by
# bench_scan (twin vs body IoU); more on the neck moves its smallest girth up into the head instead.
_LENGTHEN_SHARE = {"neck": 1.0, "thigh": 2.0, "calf": 2.0, "upper_arm": 2.0}
NECK_TIP = 0.9  # a piece the neck's section cuts beyond this (of its half-length from its middle) is left as it is


class ExtraRequestError(ElliMannError):
    """A request for extra measurements that no body can meet (one line, with the amount)."""


def extra_request_problems(request, extra):
    """Lines saying which given extra measurements are outside their limits or contradict the others (with the
    amount), for a request dict of the five (cm) and a dict of extra measurements (cm)."""
    problems = []
    for key, value in extra.items():
        if key not in EXTRA_MEASUREMENTS:
            problems.append(f"{key}: not a measurement (one of {', '.join(EXTRA_MEASUREMENTS)})")
            continue
        low, high = EXTRA_ABSURD_LIMITS[key]
        if not (np.isfinite(value) and low <= value <= high):
            problems.append(f"{key} ({MEASUREMENT_LABELS[key]}) must be {low:g}-{high:g} cm, got {value:g}")
    if problems:
        return problems
    he, hi, br = request["He"], request["Hi"], request["Br"]
    rules = (
        ("thigh", hi, "Hi", "a thigh cannot be larger than the hip"),
        ("neck", br, "Br", "a neck cannot be larger than the breast"),
        (
            "calf",
            extra.get("thigh", hi),
            "thigh" if "thigh" in extra else "Hi",
            "a calf cannot be larger than the thigh",
        ),
        ("upper_arm", 0.5 * br, "Br/2", "an upper arm cannot be larger than half the breast"),
        ("crotch_height", 0.6 * he, "0.6 He", "the crotch cannot be above 0.6 He"),
        ("arm_length", 0.5 * he, "0.5 He", "the arm cannot be longer than half of He"),
    )
    for key, limit, name, why in rules:
        if key in extra and extra[key] >= limit:
            problems.append(f"{key} {extra[key]:g} cm >= {name} {limit:g} cm by {extra[key] - limit:.2f} cm: {why}")
    if "crotch_height" in extra and extra["crotch_height"] <= 0.3 * he:
        problems.append(
            f"crotch_height {extra['crotch_height']:g} cm <= 0.3 He {0.3 * he:g} cm by "
            f"{0.3 * he - extra['crotch_height']:.2f} cm: the legs cannot be that short"
        )
    return problems


def _frame_along(axis):
    """Rows of an orthonormal frame whose third is ``axis`` (a unit vector)."""
    helper = np.array([0.0, 0.0, 1.0]) if abs(axis[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    first = np.cross(helper, axis)
    first /= np.linalg.norm(first)
    return np.stack([first, np.cross(axis, first), axis])


def _section_rows(rotation, center, semi, z, mask):
    """(rows, cut, half height) of the pieces ``mask`` a horizontal section at ``z`` cuts; cut is where, from the
    piece's middle (-1 its bottom .. 1 its top)."""
    half = axis_extent(rotation, semi, 2)
    cut = (z - center[:, 2]) / half
    rows = np.nonzero(mask & (np.abs(cut) < 1.0))[0]
    return rows, cut[rows], half[rows]


def _widen_at(rotation, center, semi, z, mask, factor, lengthen_share, stretch, spread, mid_x=None):
    """Widen (factor > 1) or narrow the section at height ``z`` of the pieces ``mask`` as locally as ellipsoids
    allow. A piece cut at ``cut`` from its middle is lengthened by factor^(lengthen_share |cut|) from its far
    end (which stays: refine's girth taper), bringing its wider middle towards the section; one cut within
    1/lengthen_share of its middle is also scaled across by the rest. Scaling a whole piece across widens it
    end to end (a thigh down to the knee, outside the body), lengthening much less so. ``stretch`` (per piece,
    updated) is the log-lengthening so far: narrowing shortens a piece only back to its own length, then scales
    it across (shorter, its near end could leave a gap in its chain: the knee and calf); widening lengthens it
    up to EXTRA_FACTOR_LIMIT. ``spread`` (per piece, updated) is the log-scaling across so far, kept within
    EXTRA_FACTOR_LIMIT either way: the limit is each piece's, not the measurement factor's (a neck piece cut
    off its middle takes only part of the factor each way, so a factor limit stopped it well short of 2x).

    With ``mid_x`` (the legs) the across scaling is front to back only and each piece keeps the edge facing the
    mid-plane: a thigh grown sideways crosses into the other and drops the crotch, and the thigh's section with
    it (the heavy bodies' thigh was missed so)."""
    rows, cut, half = _section_rows(rotation, center, semi, z, mask)
    log_factor = np.log(factor)
    share = lengthen_share * np.abs(cut)
    if log_factor < 0.0:
        share = np.minimum(share, stretch[rows] / -log_factor)
    elif log_factor > 0.0:  # no piece lengthened beyond EXTRA_FACTOR_LIMIT: the rest scales it across
        share = np.minimum(share, (np.log(EXTRA_FACTOR_LIMIT) - stretch[rows]) / log_factor)
    lengthen = np.exp(share * log_factor)
    stretch[rows] += share * log_factor
    inner = axis_extent(rotation[rows], semi[rows], 0)  # a tilted piece lengthened reaches further sideways too
    anchor = center[rows, 2] - np.sign(cut) * half
    center[rows, 2] = anchor + lengthen * (center[rows, 2] - anchor)
    semi[rows] *= lengthen[:, None] ** (rotation[rows, 2, :] ** 2)
    across_share = 1.0 - np.minimum(share, 1.0)
    if log_factor != 0.0:  # no piece scaled across beyond EXTRA_FACTOR_LIMIT or below its inverse
        room = np.log(EXTRA_FACTOR_LIMIT) - np.sign(log_factor) * spread[rows]
        across_share = np.clip(np.minimum(across_share, room / abs(log_factor)), 0.0, None)
    spread[rows] += across_share * log_factor
    across = np.exp(across_share * log_factor)[:, None]
    if mid_x is None:
        semi[rows] *= across ** (1.0 - rotation[rows, 2, :] ** 2)
    else:
        semi[rows] *= across ** (rotation[rows, 1, :] ** 2)
        center[rows, 0] += np.sign(center[rows, 0] - mid_x) * (axis_extent(rotation[rows], semi[rows], 0) - inner)


def _apply(key, factor, mannequin, rotation, center, semi, stretch, spread):
    """Deform (in place) the pieces of measurement ``key`` by ``factor`` (``stretch``, ``spread``: see _widen_at)."""
    marks = MannequinLandmarks(mannequin.copy(center=center, semi_axes=semi))
    topology = mannequin.topology
    region = np.array([part.region for part in topology])
    if key == "neck":  # the section square to the neck where it is smallest, as the upper arm's in its own frame
        frame, origin, offset = neck_plane(mannequin.copy(center=center, semi_axes=semi))
        neck_rotation, neck_center = frame @ rotation, (center - origin) @ frame.T
        rows, cut, _ = _section_rows(neck_rotation, neck_center, semi, offset, np.ones(len(region), bool))
        # a piece cut at its tip adds next to nothing to the section; lengthened, its tip runs up the neck
        widened = np.zeros(len(region), bool)
        widened[rows[np.abs(cut) < NECK_TIP] if (np.abs(cut) < NECK_TIP).any() else rows] = True
        _widen_at(neck_rotation, neck_center, semi, offset, widened, factor, _LENGTHEN_SHARE[key], stretch, spread)
        center[widened] = neck_center[widened] @ frame + origin  # the pieces widened (the others keep their bits)
    elif key in ("thigh", "calf"):
        legs = marks.leg_mask("L") | marks.leg_mask("R")
        crotch = marks.crotch()
        if key == "thigh":
            z = marks.bottom + crotch - THIGH_DROP * marks.height
        else:  # the height of the largest calf girth, on a grid over the band (enough to pick the pieces)
            heights = marks.bottom + np.linspace(*CALF_BAND, 48) * crotch
            z = heights[int(np.argmax(marks.girths_at(heights, marks.leg_mask("L"))))]
        _widen_at(rotation, center, semi, z, legs, factor, _LENGTHEN_SHARE[key], stretch, spread, mid_x=marks.mid_x)
    elif key == "crotch_height":
        crotch = marks.bottom + marks.crotch()
        lower = np.isin(region, ("legs", "feet"))
        center[lower, 2] = marks.bottom + factor * (center[lower, 2] - marks.bottom)
        center[~lower, 2] += (factor - 1.0) * (crotch - marks.bottom)
        semi[lower] *= factor ** (rotation[lower, 2, :] ** 2)  # each local axis by its share along z
    elif key in ("upper_arm", "arm_length"):
        for side in SIDES:
            start, axis, length = marks.arm_axis(side)
            arm = np.nonzero(marks.arm & (marks.side == side))[0]
            if key == "upper_arm":  # the section across the arm, as a horizontal one in the arm's own frame
                frame = _frame_along(axis)
                origin = start + UPPER_ARM_FRACTION * length * axis
                arm_rotation, arm_center, arm_semi = frame @ rotation[arm], (center[arm] - origin) @ frame.T, semi[arm]
                arm_stretch, arm_spread = stretch[arm], spread[arm]
                _widen_at(
                    arm_rotation,
                    arm_center,
                    arm_semi,
                    0.0,
                    np.ones(len(arm), bool),
                    factor,
                    _LENGTHEN_SHARE[key],
                    arm_stretch,
                    arm_spread,
                )
                center[arm], semi[arm] = arm_center @ frame + origin, arm_semi
                stretch[arm], spread[arm] = arm_stretch, arm_spread
            else:  # the arm stretched along itself about the shoulder point: an affine map, so pieces that touch
                # keep touching (scaling each piece's own axes by their share along the arm opened the fingers off
                # the hand by 2 mm at 5 % longer)
                along = np.eye(3) + (factor - 1.0) * np.outer(axis, axis)
                center[arm] = start + (center[arm] - start) @ along
                rotation[arm], semi[arm] = linear_image(rotation[arm], semi[arm], along)


def meet_extra(mannequin, extra, tolerance_cm=EXTRA_TOLERANCE_CM, max_rounds=EXTRA_MAX_ROUNDS):
    """Deform a synthesized mannequin until its m_T meets its request (``mannequin.measurements``) and its
    extra measurements meet ``extra`` {key: cm}. Returns (mannequin, measured {all keys: cm}, misses): the given
    extra measurements off by more than MISS_CM and, where refine could not keep them, the five off by more than
    FIVE_TOLERANCE_CM (a list of :class:`core.synthesis.misses.Miss`).

    All at once first; if that misses any, one measurement at a time (in EXTRA_MEASUREMENTS order), each kept only if it
    and those kept before are met with the five: one that the pieces cannot reach (or only by giving up the five) is
    left where the reference set puts it, and named in the misses; of the two results, the nearer to the request is
    returned (``_how_far``). The joints ride on their anchor pieces in every measured round (the neck is measured square
    to their tilt)."""
    result = _meet(mannequin, extra, tolerance_cm, max_rounds)
    if not result[2]:
        return result
    kept, current = {}, mannequin
    for key in (key for key in EXTRA_MEASUREMENTS if key in extra):
        trial = _meet(current, {**kept, key: extra[key]}, tolerance_cm, max_rounds)
        if not trial[2]:
            kept[key] = extra[key]
            current = trial[0]
    final, measured, _ = _meet(current, kept, tolerance_cm, max_rounds) if kept else (current, None, [])
    if measured is None:
        measured = _all_measured(final)
    one_at_a_time = (final, measured, _misses(measured, extra))
    # never worse than all at once: one left where the set puts it may lie centimetres off, all at once millimetres
    return min(result, one_at_a_time, key=lambda found: _how_far(found[1], found[2], extra))


def _how_far(measured, misses, extra):
    """How far a result of meet_extra is from its request, to choose between two: whether the five miss, then the
    largest miss of the given extra measurements (cm)."""
    return (
        any(miss.key in MEASUREMENTS for miss in misses),
        max(abs(measured[key] - extra[key]) for key in extra),
    )


def _all_measured(mannequin):
    five = tailor_measurements(
        mannequin.rotation,
        mannequin.center,
        mannequin.semi_axes,
        mannequin.topology.girth_mask,
        mannequin.section_fractions,
    )
    return {**dict(zip(MEASUREMENTS, (float(v) for v in five))), **mannequin_extra_measurements(mannequin)}


def _misses(measured, extra):
    """The given extra measurements further than MISS_CM from ``extra`` (:class:`core.synthesis.misses.Miss`)."""
    return [
        Miss(key, measured[key], extra[key])
        for key in EXTRA_MEASUREMENTS
        if key in extra and abs(measured[key] - extra[key]) > MISS_CM
    ]


def _meet(mannequin, extra, tolerance_cm, max_rounds):
    """meet_extra for all of ``extra`` at once."""
    targets = np.array([mannequin.measurements[key] for key in MEASUREMENTS])
    rotation, center, semi = mannequin.rotation.copy(), mannequin.center.copy(), mannequin.semi_axes.copy()
    keys = [key for key in EXTRA_MEASUREMENTS if key in extra]
    log_factor = {key: 0.0 for key in keys}
    stretch = np.zeros(len(center))  # log-lengthening of each piece by the girths so far (see _widen_at)
    spread = np.zeros(len(center))  # and log-scaling across
    limit = np.log(EXTRA_FACTOR_LIMIT)  # the girths' pieces are limited in _widen_at, each piece by its own
    slope = {key: 1.0 for key in keys}
    previous = {}
    girth = mannequin.topology.girth_mask
    fractions = mannequin.section_fractions

    anchors = None if mannequin.joints is None else anchor_indices(mannequin.topology)
    start = (mannequin.rotation, mannequin.center, mannequin.semi_axes)

    def measure():  # a snapshot: the arrays go on being deformed in place
        arrays = (rotation.copy(), center.copy(), semi.copy())
        # the joints ride on their anchor pieces (as through the five's refinement): the neck's tilt is theirs
        joints = None if anchors is None else follow_pieces(mannequin.joints, anchors, start, arrays)
        current = mannequin.copy(rotation=arrays[0], center=arrays[1], semi_axes=arrays[2], joints=joints)
        return current, mannequin_extra_measurements(current)

    def worst_miss(current, values):
        """(whether the five miss, the largest miss of the given extra ones in cm): the five come first."""
        five = tailor_measurements(current.rotation, current.center, current.semi_axes, girth, fractions)
        return (
            bool(np.any(np.abs(five - targets) > FIVE_TOLERANCE_CM)),
            max(abs(values[key] - extra[key]) for key in keys),
        )

    current, values = measure()
    best = (worst_miss(current, values), current, values)
    for _ in range(max_rounds):
        residual = {key: np.log(values[key] / extra[key]) for key in keys}
        if all(abs(values[key] - extra[key]) <= tolerance_cm for key in keys):
            break
        for key in keys:
            if key in previous and abs(log_factor[key] - previous[key][0]) > 1e-9:
                secant = (residual[key] - previous[key][1]) / (log_factor[key] - previous[key][0])
                slope[key] = secant if secant > 0.05 else slope[key]
            previous[key] = (log_factor[key], residual[key])
        for key in keys:
            scales_whole = key not in EXTRA_GIRTHS  # its factor scales its pieces as they are
            if scales_whole and abs(log_factor[key]) >= limit:
                continue  # at its limit: this measurement is as close as its pieces go
            step = float(np.clip(-residual[key] / slope[key], -_MAX_LOG_STEP, _MAX_LOG_STEP))
            wanted = float(np.clip(log_factor[key] + step, -limit, limit)) if scales_whole else log_factor[key] + step
            _apply(key, np.exp(wanted - log_factor[key]), current, rotation, center, semi, stretch, spread)
            log_factor[key] = wanted
            current = mannequin.copy(rotation=rotation, center=center, semi_axes=semi)
        result = refine(
            mannequin.topology, rotation[None], center[None], semi[None], targets[None], fractions=fractions
        )
        center, semi = result.center[0], result.semi_axes[0]
        current, values = measure()
        worst = worst_miss(current, values)
        if worst < best[0]:
            best = (worst, current, values)
    # the round closest to the given extra ones among those meeting the five (the synthesized one is such a round)
    _, current, values = best
    measured = _all_measured(current)
    misses = _misses(measured, extra)
    if worst_miss(current, values)[0]:  # what refine could not keep of the five, as misses too
        misses += [
            Miss(key, measured[key], mannequin.measurements[key])
            for key in MEASUREMENTS
            if abs(measured[key] - mannequin.measurements[key]) > FIVE_TOLERANCE_CM
        ]
    return current, measured, misses
