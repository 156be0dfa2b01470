"""Fitting one ellipsoid inside a body mesh: a frame from a vertex selection, then the largest
ellipsoid (by volume) that stays inside the body surface and within the selection's extent.

The paper traces each part so that it "fills as much space as possible while inscribed in the
reference 3D model surface". Here that is an optimisation per part:

1. Frame (:func:`principal_frame`): one axis from the area-weighted selected vertices (a limb's
   direction, or the principal axis that stands apart), the roll about it from a reference frame
   (world axes for the Base Mannequin, the Base Mannequin's part for the others), so corresponding
   parts of different bodies get consistent axes.
2. Centre and semi-axes (:func:`inscribed_ellipsoid`): maximise the volume subject to (a) no body
   vertex inside the ellipsoid, up to a slack and a small share of the surface (the odd interior
   vertex of eyes or mouth, a skin fold), and (b) the ellipsoid inside the selection's bounding box
   in that frame, enlarged by a margin so that neighbouring parts overlap. For a fixed centre,
   growing one semi-axis while the others are fixed has a closed-form limit per vertex; growing
   all three together in small steps converges to a maximal ellipsoid. The centre is improved by a
   deterministic pattern search.
"""

import numpy as np

from ellimann_addon.core.frames import relabel_to_reference

DEGENERATE = 0.12  # relative gap below which two principal variances do not fix their axes
GROWTH = 1.15  # largest growth of a semi-axis per round: keeps the ascent from favouring one axis
ROUNDS = 60
BISECTIONS = 12  # to find how far a round's growth stays feasible
PATTERN_STEPS = 5  # halvings of the centre search step


FRAMES = ("limb", "main", "fixed")
LIMB_END = 1.0 / 3.0  # share of the points (by area) at each end of a limb whose centroids give its axis


def principal_frame(points, weights, reference=None, frame="main", match=None):
    """Right-handed frame of a part from its weighted points: (rotation, centroid, axis index).

    One axis is taken from the points; the reference axis closest to the plane normal to it,
    projected into that plane, completes the frame (so the roll about that axis is the
    reference's, world axes by default), and the axes are labelled to agree with ``reference``.
    The axis taken is:

    - ``frame`` "limb": the line through the centroids of the two ends of the part along its
      longest principal axis (or along ``match``): a limb's direction, robust to how its flesh is
      distributed (a principal axis of a thick, short thigh is not);
    - "main": the principal axis whose variance stands most apart from the other two (with
      ``match``, the well-separated principal axis closest to it);
    - "fixed": none, the frame is the reference; also when no principal axis is separated from the
      others by DEGENERATE.

    The index is the column of the axis taken in the returned rotation (None if none was taken);
    pass that column of this part's frame as ``match`` when fitting the same part on another body.
    """
    if frame not in FRAMES:
        raise ValueError(f"frame is '{frame}'; expected one of {', '.join(FRAMES)}")
    reference = np.eye(3) if reference is None else reference
    weights = weights / weights.sum()
    centroid = weights @ points
    offsets = points - centroid
    variances, axes = np.linalg.eigh((offsets * weights[:, None]).T @ offsets)
    gaps = np.diff(variances) / np.maximum(variances[1:], 1e-300)
    separated = np.minimum(np.append(gaps, np.inf), np.insert(gaps, 0, np.inf)) >= DEGENERATE
    if frame == "fixed" or not separated.any():
        return reference.copy(), centroid, None
    if frame == "limb":
        along = offsets @ (axes[:, 2] if match is None else match)
        order = np.argsort(along, kind="stable")
        share = np.cumsum(weights[order])
        low, high = order[share <= LIMB_END], order[share >= 1.0 - LIMB_END]
        kept = weights[high] @ points[high] / weights[high].sum() - weights[low] @ points[low] / weights[low].sum()
        kept = kept / np.linalg.norm(kept)
    elif match is not None:
        candidates = np.nonzero(separated)[0]
        kept = axes[:, candidates[np.argmax(np.abs(match @ axes[:, candidates]))]]
    else:
        kept = axes[:, 2] if gaps[1] >= gaps[0] else axes[:, 0]
    in_plane = reference - np.outer(kept, kept @ reference)
    first = in_plane[:, np.argmax(np.linalg.norm(in_plane, axis=0))]
    first = first / np.linalg.norm(first)
    axes = np.stack([kept, first, np.cross(kept, first)], axis=1)
    rotation, _, q = relabel_to_reference(axes, np.ones(3), reference)
    return rotation, centroid, int(np.argmax(np.abs(q[0])))


def _grow(local, area, limit, start, allowed):
    """Largest semi-axes (3,) by simultaneous growth, for points ``local`` (m, 3) relative to the centre.

    ``limit`` (3,) caps each semi-axis; points of total ``area`` up to ``allowed`` may end up inside
    (area, not count, so that a densely meshed face and a sparsely meshed back weigh alike). Each
    round proposes, for every axis, its largest feasible value with the other two fixed, then moves
    all three towards the proposal as far as stays feasible: the result does not depend on the
    order of the axes.
    """
    sq = local * local

    def feasible(semi):
        return area[sq @ (1.0 / semi ** 2) < 1.0].sum() <= allowed

    semi = np.minimum(start, limit)
    if not feasible(semi):
        return np.zeros(3)
    for _ in range(ROUNDS):
        proposal = semi.copy()
        for i in range(3):
            room = 1.0 - sq @ np.where(np.arange(3) == i, 0.0, 1.0 / semi ** 2)
            # a point with room > 0 stays outside while semi_i <= |p_i| / sqrt(room)
            bound = np.sqrt(sq[room > 0.0, i] / room[room > 0.0])
            order = np.argsort(bound, kind="stable")
            over = np.nonzero(np.cumsum(area[room > 0.0][order]) > allowed)[0]
            cap = bound[order[over[0]]] if len(over) else np.inf
            proposal[i] = max(semi[i], min(semi[i] * GROWTH, cap, limit[i]))
        if np.allclose(proposal, semi, rtol=1e-6, atol=0.0):
            break
        ratio = proposal / semi
        low, high = 0.0, 1.0
        if feasible(proposal):
            low = 1.0
        else:
            for _ in range(BISECTIONS):
                mid = 0.5 * (low + high)
                if feasible(semi * ratio ** mid):
                    low = mid
                else:
                    high = mid
        if low == 0.0:
            break
        semi = semi * ratio ** low
    return semi


def inscribed_ellipsoid(selected, weights, obstacles, obstacle_area, reference=None, margin=0.1,
                        inside_fraction=0.002, slack=0.0, frame="main", match=None, floor=-np.inf, level=None):
    """The largest ellipsoid, in the part's frame, inside the body and the selection's box.

    ``selected`` (k, 3) vertices of the part with area ``weights``; ``obstacles`` (m, 3) body
    vertices that must stay outside, with ``obstacle_area`` (m,). A vertex may lie inside down to
    (1 - ``slack``) of the normalised radius, and vertices of total area ``inside_fraction`` of the
    nearby surface deeper still. ``margin`` enlarges the selection's box on every side, as a
    fraction of its half-extent. ``reference``, ``frame``, ``match``: see :func:`principal_frame`.
    ``floor``: world z the box may not reach below (along the local axis closest to vertical; exact
    for a "fixed" frame), to keep a part clear of a section it must not cut. ``level``: world z of the
    centre, if given (same axis): a part centred on the section it makes is cut where its girth
    changes least with height, so interpolated mannequins whose parts sit a little higher or lower
    still measure what their references do.
    Returns (rotation, center, semi_axes, kept axis index).
    """
    rotation, centroid, kept = principal_frame(selected, weights, reference, frame, match)
    local_sel = (selected - centroid) @ rotation
    lo, hi = local_sel.min(axis=0), local_sel.max(axis=0)
    half = 0.5 * (hi - lo)
    lo, hi = lo - margin * half, hi + margin * half
    up = int(np.argmax(np.abs(rotation[2])))
    if np.isfinite(floor):
        bound = (floor - centroid[2]) / rotation[2, up]
        if rotation[2, up] > 0.0:
            lo[up] = max(lo[up], bound)
        else:
            hi[up] = min(hi[up], bound)
    box_centre = 0.5 * (lo + hi)
    local_obs = (obstacles - centroid) @ rotation
    near = np.all((local_obs > lo) & (local_obs < hi), axis=1)
    local_obs, area = local_obs[near], obstacle_area[near]
    allowed = inside_fraction * area.sum()

    def solve(centre):
        limit = np.minimum(centre - lo, hi - centre)
        if np.any(limit <= 0.0):
            return 0.0, np.zeros(3)
        # a vertex may lie inside the ellipsoid down to (1 - slack) of its normalised radius
        semi = _grow((local_obs - centre) / (1.0 - slack), area, limit, 0.05 * half + 1e-4, allowed)
        return float(np.prod(semi)), semi

    centre = box_centre.copy()
    free = [0, 1, 2]
    if level is not None:
        centre[up] = (level - centroid[2]) / rotation[2, up]
        free.remove(up)
    best, semi = solve(centre)
    step = 0.25 * (hi - lo) / 2.0
    for _ in range(PATTERN_STEPS):
        while True:
            # best of the moves (not the first improving one), so the search has no preferred axis or sign
            trials = [centre + sign * step * np.eye(3)[axis] for axis in free for sign in (1.0, -1.0)]
            results = [solve(trial) for trial in trials]
            k = int(np.argmax([value for value, _ in results]))
            if results[k][0] <= best * (1.0 + 1e-9):
                break
            centre, (best, semi) = trials[k], results[k]
        step = 0.5 * step
    return rotation, centroid + rotation @ centre, semi, kept


def moments_ellipsoid(selected, weights, reference=None, frame="main", match=None):
    """The ellipsoid with the selection's area-weighted second moments (D_i = sqrt(3 var_i)).

    For parts that no ellipsoid can fill while inscribed, e.g. spread fingers: this one is the
    envelope of the part, as a mitten is of a hand.
    """
    rotation, centroid, kept = principal_frame(selected, weights, reference, frame, match)
    local = (selected - centroid) @ rotation
    variance = (weights / weights.sum()) @ (local * local)
    return rotation, centroid, np.sqrt(3.0 * variance), kept
