"""Fitting one ellipsoid inside a body mesh: a frame from a vertex selection, then an ellipsoid that
stays inside the body surface and within the selection's extent and fills as much of it as it can.

The paper traces each part so that it "fills up as much space as possible while making sure the
ellipsoids are inscribed" in the reference 3D model. Here that is an optimisation per part:

1. Frame (:func:`principal_frame`): one axis from the area-weighted selected vertices (a limb's
   direction, or the principal axis that stands apart), the roll about it from a reference frame
   (world axes for the Base Mannequin, the Base Mannequin's part for the others), so corresponding
   parts of different bodies get consistent axes.
2. Centre and semi-axes (:func:`inscribed_ellipsoid`): subject to (a) no obstacle point inside the
   ellipsoid but a small share of the surface (the caller passes the body's vertices moved out by
   a few mm, so that a part may bulge that far rather than leave a gap), (b) the ellipsoid inside
   the selection's bounding box in that frame, enlarged by a margin so that neighbouring parts
   overlap, and (c) optionally clear of given heights. For a fixed centre, growing one semi-axis
   while the others are fixed has a closed-form limit per point; growing all three together in
   small steps converges to a maximal ellipsoid, whose shape depends on the shape it starts from.
   A deterministic pattern search over the centre and that starting shape then keeps the maximal
   ellipsoid that covers most of the body's volume inside the box (or, without volume samples,
   the largest one).
"""

import numpy as np

from ..geometry.cushion import convex_hull_3d
from ..geometry.ellipsoid import to_frame
from ..geometry.frames import relabel_to_reference
from ..geometry.mesh import face_normals

MIDLINE_ALIGNED = 0.99  # |cos| between world x and the frame's axis a central part's centre keeps still along
DEGENERATE = 0.12  # relative gap below which two principal variances do not fix their axes
GROWTH = 1.15  # largest growth of a semi-axis per round: keeps the ascent from favouring one axis
ROUNDS = 60  # of the growth towards a maximal ellipsoid, at most
# Relative growth below which the ascent has stopped: so small that stopping a round earlier or later
# moves nothing, so the result does not hinge on rounding (a coarser test would).
STALLED = 1e-12
ENTRY_NEWTON = 30  # Newton steps to where a point enters the growing ellipsoid (converges from one side), at most
# Newton has converged when no entry time moves by more than this: the next step would be ~ its square, while the
# last steps of a converged iteration only jitter by rounding (some 1e-16), which no fixed count should sample.
ENTRY_SETTLED = 1e-10
# A step stops where the point it meets is this far out (in sum (x_k / D_k)^2 - 1): far above rounding,
# so that point is outside in every later test, not inside or outside by the last bit.
CONTACT = 1e-12
PATTERN_STEPS = 5  # halvings of the centre search step
SHAPE_STEP = 0.4  # first step of the search over the starting shape (log ratio of semi-axes)
TIE = 1e-10  # relative difference below which two values of the search are the same (rounding is ~1e-14)


FRAMES = ("limb", "main", "axis", "fixed")
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
    - "axis": ``match`` itself (a limb whose longest extent is not along it: a short, thick neck);
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
    if frame == "axis":
        if match is None:
            raise ValueError("an 'axis' frame needs the axis (match)")
        kept = np.asarray(match, dtype=float) / np.linalg.norm(match)
    elif frame == "fixed" or not separated.any():
        return reference.copy(), centroid, None
    elif frame == "limb":
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


def _grow(local, area, limit, start, allowed, up=None, reach=np.inf):
    """Largest semi-axes (3,) by simultaneous growth, for points ``local`` (m, 3) relative to the centre.

    ``limit`` (3,) caps each semi-axis; points of total ``area`` up to ``allowed`` may end up inside
    (area, not count, so that a densely meshed face and a sparsely meshed back weigh alike). With
    ``up`` (3,), the world-z component of each local axis, the ellipsoid's half-height
    sqrt(sum (up_k D_k)^2) may not exceed ``reach``. Each round proposes, for every axis, its largest
    feasible value with the other two fixed, then moves all three towards the proposal as far as
    stays feasible: the result does not depend on the order of the axes.
    """
    sq = local * local
    up2 = np.zeros(3) if up is None else np.asarray(up) ** 2
    bounded = np.isfinite(reach) and np.any(up2 > 0.0)
    reach2 = reach**2 * (1.0 + 1e-12)

    def feasible(sq, area, semis):  # (k, 3) candidates -> (k,) bool
        inside = np.einsum("mk,kc->mc", sq, 1.0 / semis.T**2) < 1.0
        return (np.einsum("m,mc->c", area, inside) <= allowed) & (semis**2 @ up2 <= reach2)

    semi = np.minimum(start, limit)
    if not feasible(sq, area, semi[None])[0]:
        return np.zeros(3)
    all_sq, all_area = sq, area
    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(ROUNDS):
            inv = 1.0 / semi**2
            radius = np.einsum("mk,k->m", all_sq, inv)
            # a round grows no axis by more than GROWTH: points this far out stay out whatever it does
            near = radius < GROWTH**2
            sq, area, radius = all_sq[near], all_area[near], radius[near]
            cap = limit.copy()
            if len(sq):
                # a point a step stopped at (CONTACT out) is on the surface: it blocks every axis it has a
                # component along, rather than letting one creep on by a margin that rounding would set
                on = np.where(radius < 1.0 + 2.0 * CONTACT, np.minimum(radius, 1.0), radius)
                room = 1.0 - on[:, None] + sq * inv  # (m, 3): with the other two axes as they are
                # A point with room > 0 stays outside while semi_i <= |p_i| / sqrt(room). Only bounds below
                # what the round may propose anyway can cap it: those are few, and only they are sorted.
                below = (room > 0.0) & (sq < np.minimum(limit, semi * GROWTH) ** 2 * room)
                for k in np.nonzero(np.einsum("m,mk->k", area, below) > allowed)[0]:
                    rows = np.nonzero(below[:, k])[0]
                    bound = np.sqrt(sq[rows, k] / room[rows, k])
                    order = np.argsort(bound)
                    # the bound at which the points inside would exceed the allowed area
                    cap[k] = min(cap[k], bound[order[np.argmax(np.cumsum(area[rows][order]) > allowed)]])
            if bounded:
                rest = reach**2 - up2 @ semi**2 + up2 * semi**2
                cap = np.where(up2 > 0.0, np.minimum(cap, np.sqrt(np.maximum(rest, 0.0) / up2)), cap)
            proposal = np.maximum(semi, np.minimum(semi * GROWTH, cap))
            if np.all(proposal <= semi * (1.0 + STALLED)):
                break
            rate = np.log(proposal / semi)
            t = _furthest_feasible(sq * inv, area, rate, allowed)
            if bounded:
                t = min(t, _within_reach(up2 * semi**2, rate, reach2))
            if np.all(t * rate <= STALLED):  # blocked: the next round would propose the same
                break
            semi = semi * np.exp(t * rate)
    return semi


def _furthest_feasible(scaled, area, rate, allowed):
    """Largest t in [0, 1] for which the points of total ``area`` inside the ellipsoid of semi-axes
    semi * exp(t * rate) stay within ``allowed``; ``scaled`` (m, 3): squared coordinates over semi^2.

    The exact time each point meets the surface (CONTACT outside it), a continuous function of the
    points, where trying a fixed set of steps would jump from one step to the next as a point moves
    across it: along the path every semi-axis grows, so each point's g(t) = sum_k scaled_k
    exp(-2 rate_k t) decreases, convex; Newton from t = 0 approaches g = 1 + CONTACT from below.
    """
    g0 = scaled.sum(axis=1)
    g1 = np.einsum("mk,k->m", scaled, np.exp(-2.0 * rate))
    entering = (g0 >= 1.0) & (g1 < 1.0 + CONTACT)
    inside = area[g0 < 1.0].sum()
    if inside > allowed:
        return 0.0
    if inside + area[entering].sum() <= allowed:
        return 1.0
    a, b = scaled[entering], 2.0 * rate
    t = np.zeros(len(a))
    for _ in range(ENTRY_NEWTON):
        terms = a * np.exp(-np.outer(t, b))
        step = (terms.sum(axis=1) - 1.0 - CONTACT) / np.maximum(np.einsum("mk,k->m", terms, b), 1e-300)
        moved = np.clip(t + step, 0.0, 1.0)
        settled = np.abs(moved - t).max() <= ENTRY_SETTLED
        t = moved
        if settled:
            break
    order = np.argsort(t, kind="stable")
    over = inside + np.cumsum(area[entering][order]) > allowed
    return float(t[order][np.argmax(over)])


def _within_reach(weighted, rate, reach2):
    """Largest t in [0, 1] with sum_k weighted_k exp(2 rate_k t) <= reach2 (the half-height bound)."""

    def height2(t):
        return weighted @ np.exp(2.0 * rate * t)

    if height2(1.0) <= reach2:
        return 1.0
    lo, hi = 0.0, 1.0
    for _ in range(60):  # bisection to 1e-18: fixed, so the result moves smoothly with the inputs
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if height2(mid) <= reach2 else (lo, mid)
    return lo


def inscribed_ellipsoid(
    selected,
    weights,
    obstacles,
    obstacle_area,
    reference=None,
    margin=0.1,
    inside_fraction=0.002,
    frame="main",
    match=None,
    floor=-np.inf,
    ceiling=np.inf,
    level=None,
    span=False,
    fill=None,
    fill_weight=None,
    fill_spacing=None,
    midline=False,
):
    """A maximal ellipsoid, in the part's frame, inside the body and the selection's box.

    ``selected`` (k, 3) vertices of the part with area ``weights``; ``obstacles`` (m, 3) body
    vertices that must stay outside, with ``obstacle_area`` (m,), except vertices of total area
    ``inside_fraction`` of the nearby surface. ``margin`` enlarges the selection's box on every side, as a
    fraction of its half-extent. ``reference``, ``frame``, ``match``: see :func:`principal_frame`.
    ``floor``, ``ceiling``: world heights the ellipsoid may not reach below or above, to keep a part
    clear of a section it must not cut. ``level``: world z of the centre, if given: a part centred on
    the section it makes is cut where its girth changes least with height, so interpolated
    mannequins whose parts sit a little higher or lower still measure what their references do.
    ``span``: the semi-axis along the axis taken from the points is the box's half-length along it
    (less if ``floor`` or ``ceiling`` allow less), and the centre the box's middle there: a limb's
    part reaches from one end of its segment to the other, however the limb tapers (only the
    cross-section grows). ``fill``: the centres (p, 3) of the cells of a regular grid of
    ``fill_spacing`` sampling the body's volume; if given, the centre is chosen for the
    ellipsoid to cover most of them (by :func:`cell_share`) within the box, instead of for the largest ellipsoid: a part
    fills its region rather than settling where the body is thickest. ``fill_weight`` (p,): what
    covering each point is worth (default 1), e.g. less where other parts already cover it, or less than nothing
    outside the body. ``midline``: the centre
    stays in the box's middle across the frame's axis along world x (a central part, which the mannequin makes
    symmetric about that middle afterwards: fitted off it, it would be moved into a body it was not fitted to).
    Returns (rotation, center, semi_axes, kept axis index).
    """
    rotation, centroid, kept = principal_frame(selected, weights, reference, frame, match)
    if span and kept is None:
        raise ValueError("span needs an axis taken from the points (a 'limb', 'axis' or 'main' frame that finds one)")
    local_sel = to_frame(selected, centroid, rotation)
    lo, hi = local_sel.min(axis=0), local_sel.max(axis=0)
    half = 0.5 * (hi - lo)
    lo, hi = lo - margin * half, hi + margin * half
    up = int(np.argmax(np.abs(rotation[2])))
    box_centre = 0.5 * (lo + hi)
    local_obs = to_frame(obstacles, centroid, rotation)
    near = np.all((local_obs > lo) & (local_obs < hi), axis=1)
    local_obs, area = local_obs[near], obstacle_area[near]
    allowed = inside_fraction * area.sum()
    if fill is not None:
        fill = to_frame(fill, centroid, rotation)
        # every cell the ellipsoid (inside the box) can share, however the box moves
        in_box = np.all((fill > lo - fill_spacing) & (fill < hi + fill_spacing), axis=1)
        fill = fill[in_box]
        fill_weight = np.ones(len(fill)) if fill_weight is None else np.asarray(fill_weight)[in_box]

    def solve(centre, shape):
        limit = np.minimum(centre - lo, hi - centre)
        z = centroid[2] + rotation[2] @ centre
        reach = min(z - floor, ceiling - z)
        if np.any(limit <= 0.0) or reach <= 0.0:
            return 0.0, np.zeros(3)
        start = 0.05 * half * shape + 1e-4
        if span:  # as long as the box and the heights it must keep clear of let it be
            start[kept] = min(limit[kept], reach / max(abs(rotation[2, kept]), 1e-12))
        semi = _grow(local_obs - centre, area, limit, start, allowed, rotation[2], reach)
        if fill is None or not np.all(semi > 0.0):
            return float(np.prod(semi)), semi
        # covered volume; the ellipsoid's own volume (tiny weight) breaks ties
        covered = np.einsum("p,p->", fill_weight, cell_share(fill - centre, semi, fill_spacing))
        return covered + 1e-3 * float(np.prod(semi)) / float(np.prod(half)), semi

    centre = box_centre.copy()
    free = [0, 1, 2]
    if span:
        free.remove(kept)
    if level is not None and up in free:
        free.remove(up)
    if midline:
        across = int(np.argmax(np.abs(rotation[0])))  # the frame's axis nearest world x
        if across in free and abs(rotation[0, across]) > MIDLINE_ALIGNED:
            free.remove(across)
    # Searched: the free coordinates of the centre and, when filling, the shape the growth starts
    # from (log ratios of two semi-axes to the third), which decides the maximal ellipsoid it reaches.
    shaped = [] if fill is None else [k for k in range(3) if k != kept][1:] if span else [1, 2]

    def unpack(x):
        c = centre.copy()
        c[free] = x[: len(free)]
        if level is not None:  # the centre's height stays the level whatever the other coordinates
            c[up] = (level - centroid[2] - rotation[2] @ (c * (np.arange(3) != up))) / rotation[2, up]
        shape = np.ones(3)
        shape[shaped] = np.exp(x[len(free) :])
        return c, shape

    solved = {}  # a move's way back is the point it came from, bit for bit more often than not

    def solve_at(x):
        key = x.tobytes()
        if key not in solved:
            solved[key] = solve(*unpack(x))
        return solved[key]

    x = np.concatenate([centre[free], np.zeros(len(shaped))])
    step = np.concatenate([0.25 * (hi - lo)[free] / 2.0, np.full(len(shaped), SHAPE_STEP)])
    best, semi = solve_at(x)
    for _ in range(PATTERN_STEPS):
        while True:
            # best of the moves (not the first improving one), so the search has no preferred axis or sign
            trials = [x + sign * step[k] * np.eye(len(x))[k] for k in range(len(x)) for sign in (1.0, -1.0)]
            results = [solve_at(trial) for trial in trials]
            values = np.array([value for value, _ in results])
            # Trials within TIE of the best are equal: different starting shapes often grow into the same
            # ellipsoid, equal up to rounding, and rounding must not pick one. The first of them is taken.
            k = int(np.argmax(values >= values.max() - TIE * abs(values.max())))
            # a move must gain a little: above the best, also when a cover that pays for the outside is negative
            if values[k] <= best * (1.0 + 1e-9 if best >= 0.0 else 1.0 - 1e-9):
                break
            x, (best, semi) = trials[k], results[k]
        step = 0.5 * step
    centre, _ = unpack(x)
    return rotation, centroid + rotation @ centre, semi, kept


def cell_share(local, semi_axes, spacing):
    """Share (0..1) of the cells of size ``spacing`` centred at ``local`` (p, 3) inside the ellipsoid of
    ``semi_axes`` (3,) about the origin, in its frame: 1/2 + signed distance to the surface / spacing,
    clipped, the distance to first order (1 - g) / |grad g| of g = sum (x_k / D_k)^2.

    A share, not an inside test, so the volume an ellipsoid covers changes continuously as it or the
    cells move: with a count, a cell centre crossing the surface by rounding would decide a search.
    """
    scaled = local / semi_axes
    g = np.einsum("pk,pk->p", scaled, scaled)
    over = scaled / semi_axes
    gradient = 2.0 * np.sqrt(np.einsum("pk,pk->p", over, over))
    with np.errstate(divide="ignore"):
        distance = (1.0 - g) / gradient  # +inf at the centre
    return np.clip(0.5 + distance / spacing, 0.0, 1.0)


def hull_surface(points, depth=0.0, spacing=0.003):
    """Points on the convex hull of ``points``, moved out by ``depth``, about ``spacing`` apart, with
    the area each stands for: (points (m, 3), areas (m,)).

    As obstacles they keep a part inside the hull of its own vertices: a mitten over spread fingers,
    which no ellipsoid inside the body surface could fill.
    """
    faces = convex_hull_3d(points)
    normals = face_normals(points, faces)
    out, areas = [], []
    for simplex, normal in zip(faces, normals):
        a, b, c = points[simplex]
        area = 0.5 * np.linalg.norm(normal)
        normal = normal / np.linalg.norm(normal)
        k = max(1, int(np.ceil(np.sqrt(2.0 * area) / spacing)))
        i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
        keep = i + j <= k
        u, v = i[keep] / k, j[keep] / k
        out.append(a + u[:, None] * (b - a) + v[:, None] * (c - a) + depth * normal)
        areas.append(np.full(len(u), area / len(u)))
    return np.concatenate(out), np.concatenate(areas)
