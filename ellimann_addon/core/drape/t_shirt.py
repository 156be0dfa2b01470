"""The T-shirt garment (``core.drape.garments.t_shirt``): front and back panels over the chest and shoulder blades, sewn
at the shoulders, and two sleeves sewn to the armholes. See ``core.drape.garments`` for the method."""

import numpy as np

from ..constants import CM_PER_M
from ..errors import ElliMannError
from ..geometry.ellipsoid import axis_extent, section_at_height
from ..geometry.mesh import face_normals
from ..measure.tailor import hull_perimeter
from ..settings import DEFAULT_EDGE, EDGE_RANGE
from .fit_metrics import ellipsoid_signed_distance
from .patterns import (
    MIN_CLEARANCE,
    RING_SAMPLES,
    Garment,
    body_extent,
    check_range,
    clear_rows,
    fill_gaps,
    girth_perimeters,
    grid_faces,
    hull_rings,
    pattern_measurements,
    resample_polyline,
    section_ellipses,
)

# ----------------------------------------------------------------------------------------------
# T-shirt


def pattern_girth(sizes, heights, bottom, height, fractions):
    """Pattern girth (m) at each height: Hi below the hip line, Br above the bust line, linear between (the lines
    at ``fractions``, the mannequin's section heights)."""
    keys = ("Hi", "Wa", "Br")
    at = [bottom + fractions[key] * height for key in keys]
    values = [sizes[key] / CM_PER_M for key in keys]
    return np.interp(heights, at, values)


def _upper_arm(mannequin, side):
    """Index of the highest part of ``side`` whose region names an arm, or None."""
    best = None
    for i, part in enumerate(mannequin.topology):
        if part.side == side and "arm" in part.region.lower() and "fore" not in part.region.lower():
            if best is None or mannequin.center[i, 2] > mannequin.center[best, 2]:
                best = i
    return best


def silhouette_top(mannequin, x):
    """Top of the body's frontal silhouette (projection along Y) at each lateral x: (X,), -inf if none."""
    m = mannequin.rotation * mannequin.semi_axes[:, None, :] ** 2 @ np.swapaxes(mannequin.rotation, 1, 2)
    mxx, mxz, mzz = m[:, 0, 0], m[:, 0, 2], m[:, 2, 2]
    dx = np.asarray(x, float)[:, None] - mannequin.center[None, :, 0]
    inside = 1.0 - dx * dx / mxx
    top = mannequin.center[None, :, 2] + dx * mxz / mxx + np.sqrt(np.clip((mzz - mxz**2 / mxx) * inside, 0, None))
    return np.where(inside > 0.0, top, -np.inf).max(axis=1)


def _chain_y(polygons, x, front):
    """y of each ring polygon (N, M, 2) on its front (min y) or back chain at lateral x (N,).

    A point outside the ring's x-range takes the y of the ring's extreme point: still outside the
    ring, so still outside the body.
    """
    out = np.empty(len(x))
    half = polygons.shape[1] // 2
    for i, (poly, xi) in enumerate(zip(polygons, x)):
        # Directions pi..2pi trace the front chain from the -X extreme to the +X extreme; 0..pi the back
        # chain from +X to -X. Both are monotonic in x for a convex ring.
        chain = np.concatenate([poly[half:], poly[:1]]) if front else poly[: half + 1][::-1]
        out[i] = np.interp(xi, chain[:, 0], chain[:, 1])
    return out


def t_shirt(
    mannequin,
    ease=0.08,
    sleeve_ease=0.3,
    edge=DEFAULT_EDGE,
    measurements=None,
    hem=0.45,
    sleeve_length=0.09,
    clearance=0.012,
):
    """A short-sleeved T-shirt: front and back panels with sleeves, sewn round the body.

    ``ease`` is added to the Hi/Wa/Br pattern girths, ``sleeve_ease`` to the upper arm's girth;
    ``hem`` and ``sleeve_length`` are fractions of He; ``clearance`` (m) is the initial gap of the
    yoke and sleeves above the body. Panels: 0 body (tube below the armpit), 1 front yoke,
    2 back yoke, 3 left sleeve, 4 right sleeve. Seams: shoulders (front top edge to back top edge,
    outside the neck opening) and armholes (sleeve top ring to the armhole edge).
    """
    mannequin.check()
    ease = check_range("ease", ease, 0.0, 1.0)
    sleeve_ease = check_range("sleeve_ease", sleeve_ease, 0.0, 2.0)
    edge = check_range("edge", edge, *EDGE_RANGE)
    fractions = mannequin.section_fractions  # the garment's lines sit where m_T measures the mannequin
    hem = check_range("hem", hem, 0.2, fractions["Hi"])
    sleeve_length = check_range("sleeve_length", sleeve_length, 0.02, 0.3)
    clearance = check_range("clearance", clearance, MIN_CLEARANCE, 0.1)
    sizes = pattern_measurements(mannequin, measurements)
    topology = mannequin.topology
    arms = {side: _upper_arm(mannequin, side) for side in ("L", "R")}
    if arms["L"] is None or arms["R"] is None:
        raise ElliMannError("mannequin: a T-shirt needs a left and a right part whose region names an arm")
    bottom, height = body_extent(mannequin)
    girth = topology.girth_mask
    z_sh = bottom + fractions["Sh"] * height

    # 1. Body tube, from the hem up to the armpit: the highest height below which every ring stays
    #    clear of every part (the arms included) by half the minimum clearance.
    z_hem = bottom + hem * height
    # Rings every edge length, plus one exactly on each girth line so the pattern girths are exact there.
    lines = [bottom + fractions[key] * height for key in ("Hi", "Wa", "Br")]
    z = np.arange(z_hem, z_sh, edge)
    z = np.sort(np.concatenate([z[np.min(np.abs(z[:, None] - np.array(lines)), axis=1) > edge / 3], lines]))
    perimeter, (centre, k, active) = girth_perimeters(mannequin, girth, z)
    pattern = pattern_girth(sizes, z, bottom, height, fractions) * (1.0 + ease)
    width = np.maximum(pattern, perimeter + 2.0 * np.pi * MIN_CLEARANCE)
    columns = 2 * max(6, int(np.ceil(width.max() / (2.0 * edge))))  # even: front and back halves
    polygons = hull_rings(centre, k, active, (width - perimeter) / (2.0 * np.pi))
    half = RING_SAMPLES // 2
    # Ring nodes: the -X extreme (right side), the front chain, the +X extreme (left side), the back.
    rings = np.stack(
        [
            np.concatenate(
                [
                    resample_polyline(np.concatenate([p[half:], p[:1]]), columns // 2 + 1, closed=False)[:-1],
                    resample_polyline(p[: half + 1], columns // 2 + 1, closed=False)[:-1],
                ]
            )
            for p in polygons
        ]
    )
    ring_points = np.concatenate([rings, np.broadcast_to(z[:, None, None], rings.shape[:2] + (1,))], axis=-1)
    top_row = clear_rows(mannequin, ring_points) - 1
    if top_row < 1:
        raise ElliMannError("mannequin: the arms leave no room for a T-shirt body above the hem")
    tube = ring_points[: top_row + 1]
    z_armpit = z[top_row]
    n_front = columns // 2  # front chain segments; front nodes 0..n_front, back nodes n_front..columns

    # 2. Yoke: front and back panels from the armpit ring up to just below the shoulder line. Column j
    #    starts at armpit ring node j and slants to x * spread at the top, where the top edge follows
    #    the shoulder silhouette (boat neck across the neck opening). Each node sits on the front or
    #    back of an offset ring through every part at its own height.
    half_x, half_z = (axis_extent(mannequin.rotation, mannequin.semi_axes, axis) for axis in (0, 2))
    neck_parts = [i for i, p in enumerate(topology) if p.side == "C" and mannequin.center[i, 2] - half_z[i] > z_sh]
    neck = max((float(half_x[i]) for i in neck_parts), default=0.05 * height) + clearance
    # The shoulder point: half the shoulder width, but not beyond the top of the upper arm (where
    # the sleeve starts) for bodies whose arms are not hung from the shoulders' outer edge.
    arm_top = max(_arm_top_x(mannequin, arms[side]) for side in ("L", "R"))
    shoulder = max(min(sizes["Sh"] / CM_PER_M / 2.0, arm_top), neck + 2.0 * edge)
    side_x = tube[-1, n_front, 0]
    spread = shoulder / side_x
    x_top = tube[-1, :, 0] * spread
    z_edge = silhouette_top(mannequin, np.maximum(np.abs(x_top), neck)) - clearance
    z_edge = np.maximum(z_edge, z_armpit + 2.0 * edge)  # the yoke always rises
    yoke_rows = max(2, int(np.ceil((z_edge.max() - z_armpit) / edge)) + 1)
    t = np.linspace(0.0, 1.0, yoke_rows)[:, None]
    yx = tube[-1, None, :, 0] * (1.0 + (spread - 1.0) * t)
    yz = z_armpit + (z_edge[None, :] - z_armpit) * t
    every = np.ones(len(topology), dtype=bool)
    flat_z = yz[1:].ravel()
    centre, k, active = section_ellipses(mannequin, every, flat_z)
    ring = hull_rings(centre, k, active, np.full(len(flat_z), clearance))
    front_cols = np.arange(n_front + 1)
    back_cols = np.r_[np.arange(n_front, columns), 0]
    yy = np.zeros_like(yx)
    yy[0] = tube[-1, :, 1]
    flat_x = yx[1:].ravel()
    is_front = np.zeros(yx.shape[1], dtype=bool)
    is_front[front_cols] = True
    flat_front = np.broadcast_to(is_front, yx[1:].shape).ravel()
    y = np.empty(len(flat_x))
    y[flat_front] = _chain_y(ring[flat_front], flat_x[flat_front], front=True)
    y[~flat_front] = _chain_y(ring[~flat_front], flat_x[~flat_front], front=False)
    yy[1:] = y.reshape(yoke_rows - 1, -1)
    # The armpit ring's side nodes (0 and n_front) are shared by front and back: rows above split.
    yoke = np.stack([yx, yy, yz], axis=-1)  # (rows, columns, 3), row 0 = the armpit ring

    # 3. Assemble body tube + yokes. Vertex ids: tube rows, then front yoke rows 1.., back yoke rows 1..
    vertices = [tube.reshape(-1, 3)]
    faces = [grid_faces(len(tube), columns, closed=True)]
    panel = [np.zeros(tube.shape[0] * columns, dtype=int)]
    base = len(vertices[0])
    armpit_ids = (len(tube) - 1) * columns + np.arange(columns)
    yoke_ids = {}
    for which, cols in ((1, front_cols), (2, back_cols)):
        ids = np.empty((yoke_rows, len(cols)), dtype=int)
        ids[0] = armpit_ids[cols]
        ids[1:] = base + np.arange((yoke_rows - 1) * len(cols)).reshape(yoke_rows - 1, len(cols))
        base += (yoke_rows - 1) * len(cols)
        vertices.append(yoke[1:, cols].reshape(-1, 3))
        panel.append(np.full((yoke_rows - 1) * len(cols), which))
        local = grid_faces(yoke_rows, len(cols), closed=False)
        faces.append(ids.ravel()[local])
        yoke_ids[which] = ids

    # Shoulder seams: front column j and back column mirrored across the side, outside the neck.
    front_top, back_top = yoke_ids[1][-1], yoke_ids[2][-1]
    back_by_front = back_top[::-1]  # back columns run +X -> -X from the left side; reverse to match
    outside_neck = np.abs(x_top[front_cols]) >= neck
    seams = [np.stack([front_top[outside_neck], back_by_front[outside_neck]], axis=1)]

    # 4. Sleeves round the upper arms, each top ring sewn to its armhole loop.
    vertex_array = np.concatenate(vertices)
    sleeve_vertices, sleeve_faces, sleeve_panels = [], [], []
    info = {}
    for which, side in ((3, "L"), (4, "R")):
        front_col = n_front if side == "L" else 0
        back_col = 0 if side == "L" else n_front
        loop = np.concatenate(
            [[armpit_ids[n_front if side == "L" else 0]], yoke_ids[1][1:, front_col], yoke_ids[2][1:, back_col][::-1]]
        )
        ring_nodes, ring_rows, seam_ring, data = _sleeve(
            mannequin, arms[side], loop, vertex_array, sizes, sleeve_ease, sleeve_length * height, edge, clearance
        )
        offset = base + sum(len(v) for v in sleeve_vertices)
        sleeve_vertices.append(ring_nodes.reshape(-1, 3))
        sleeve_faces.append(offset + grid_faces(ring_rows, len(loop), closed=True))
        sleeve_panels.append(np.full(ring_rows * len(loop), which))
        seams.append(np.stack([offset + seam_ring, loop], axis=1))
        info[side] = data
    vertices = np.concatenate([vertex_array] + sleeve_vertices)
    faces = np.concatenate(faces + sleeve_faces)
    faces = _orient_away_from_body(vertices, faces, np.concatenate(panel + sleeve_panels), mannequin)
    return Garment(
        name="T-shirt",
        vertices=vertices,
        faces=faces,
        seams=np.concatenate(seams),
        panel=np.concatenate(panel + sleeve_panels),
        panel_names=("body", "front yoke", "back yoke", "left sleeve", "right sleeve"),
        pattern={
            "girth_cm": {
                key: float(np.interp(bottom + fractions[key] * height, z, width) * CM_PER_M)
                for key in ("Br", "Wa", "Hi")
                if z_hem <= bottom + fractions[key] * height <= z_armpit
            },
            "armpit_height_cm": z_armpit * CM_PER_M,
            "hem_height_cm": z_hem * CM_PER_M,
            "shoulder_width_cm": 2 * shoulder * CM_PER_M,
            "neck_width_cm": 2 * neck * CM_PER_M,
            "sleeve_girth_cm": {s: d["girth"] * CM_PER_M for s, d in info.items()},
            "ease": ease,
            "sleeve_ease": sleeve_ease,
            "measurements_cm": sizes,
            "edge": edge,
        },
    )


def _arm_top_x(mannequin, i):
    """|x| of the outer side of an arm part's upper end: centre + half its long axis up, + its radius."""
    r, c, d = mannequin.rotation[i], mannequin.center[i], mannequin.semi_axes[i]
    long = int(np.argmax(d))
    up = r[:, long] if r[2, long] > 0 else -r[:, long]
    return float(abs(c[0] + d[long] * up[0]) + np.sort(d)[1])


def _sleeve(mannequin, arm, loop, vertices, sizes, sleeve_ease, length, edge, clearance):
    """Rings perpendicular to the upper arm's long axis, from near the armhole down ``length``.

    Returns (nodes (rows, len(loop), 3), rows, index of each top-ring node in the sleeve's own
    numbering matched to ``loop`` order, info). The top ring starts at the underarm point and
    runs over the front first, like the armhole loop (armpit, up the front, down the back).
    """
    r, c, d = mannequin.rotation[arm], mannequin.center[arm], mannequin.semi_axes[arm]
    axis = r[:, np.argmax(d)]
    axis = axis if axis[2] < 0 else -axis  # pointing down the arm
    # Frame with the arm axis as "z": e2 is world Y made perpendicular, e1 completes it.
    e2 = np.array([0.0, 1.0, 0.0]) - axis[1] * axis
    e2 /= np.linalg.norm(e2)
    e1 = np.cross(e2, axis)
    q = np.stack([e1, e2, axis], axis=1)
    same_side = np.array(
        [p.side == mannequin.topology.parts[arm].side and "arm" in p.region.lower() for p in mannequin.topology]
    )
    rot = np.einsum("ji,njk->nik", q, mannequin.rotation[same_side])
    cen = (mannequin.center[same_side] - c) @ q
    semi = mannequin.semi_axes[same_side]
    small = np.sort(d)[:2]
    girth = 2.0 * np.pi * np.sqrt(0.5 * (small[0] ** 2 + small[1] ** 2)) * (1.0 + sleeve_ease)
    # Start where the armhole is, then move down the arm until the ring clears every other part.
    armhole = vertices[loop]
    start = float(np.mean((armhole - c) @ axis))
    count = len(loop)
    for shift in np.arange(0.0, length, 0.25 * edge):
        sigma = start + shift + np.linspace(0.0, length, max(2, int(np.ceil(length / edge)) + 1))
        sections = fill_gaps(*section_at_height(rot[None], cen[None], semi[None], sigma[:, None]))
        if sections is None:
            continue
        centre, k, hit = sections
        perimeter = hull_perimeter(centre, k, hit)
        width = np.maximum(girth, perimeter + 2.0 * np.pi * clearance)
        polygons = hull_rings(centre, k, hit, (width - perimeter) / (2.0 * np.pi))
        # Underarm: the direction -up-and-out, i.e. towards the body and down, in the (e1, e2) plane.
        toward_body = np.array([-np.sign(c[0]), 0.0, 0.0]) - axis * -np.sign(c[0]) * axis[0]
        angle = np.arctan2(toward_body @ e2, toward_body @ e1)
        first = int(np.round(np.mod(angle, 2 * np.pi) / (2 * np.pi) * RING_SAMPLES)) % RING_SAMPLES
        rings = np.stack([resample_polyline(np.roll(p, -first, axis=0), count, closed=True) for p in polygons])
        # Run over the front (-Y, i.e. -e2) first, as the armhole loop does.
        if rings[0, count // 4, 1] > rings[0, 0, 1]:
            rings = np.concatenate([rings[:, :1], rings[:, :0:-1]], axis=1)
        local = np.concatenate([rings, np.broadcast_to(sigma[:, None, None], rings.shape[:2] + (1,))], axis=-1)
        world = local @ q.T + c
        gap = ellipsoid_signed_distance(
            world.reshape(-1, 3), mannequin.rotation, mannequin.center, mannequin.semi_axes
        ).min()
        if gap >= 0.5 * MIN_CLEARANCE:
            return world, len(sigma), np.arange(count), {"girth": float(width[0]), "shift": float(shift)}
    raise ElliMannError(f"mannequin: no room for a sleeve round '{mannequin.topology.names[arm]}'")


def _orient_away_from_body(vertices, faces, panel, mannequin):
    """Flip faces whose normal points towards the nearest body part (each panel is consistently wound)."""
    tri = vertices[faces]
    normal = face_normals(vertices, faces)
    centroid = tri.mean(axis=1)
    distance, closest = ellipsoid_signed_distance(
        centroid, mannequin.rotation, mannequin.center, mannequin.semi_axes, return_closest=True
    )
    nearest = closest[np.arange(len(centroid)), np.argmin(distance, axis=1)]
    outward = np.einsum("ij,ij->i", normal, centroid - nearest) > 0.0
    face_panel = panel[faces[:, 0]]
    out = faces.copy()
    for p in np.unique(face_panel):
        mine = face_panel == p
        if np.mean(outward[mine]) < 0.5:  # a panel is wound one way throughout: flip it whole
            out[mine] = out[mine][:, ::-1]
    return out
