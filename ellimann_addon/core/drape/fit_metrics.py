"""Garment-to-body distances: signed distance to ellipsoids, cushions and triangle meshes, and fit statistics.

Signs: negative inside the body (a penetration), positive outside. For a union of pieces the
distance is the minimum over pieces: exact outside the union; inside, minus the depth into the
piece a point is deepest in (what a collision solver must undo).

Point-to-ellipsoid distance solves the Lagrange condition of the nearest point in closed form up
to one scalar: in the ellipsoid's frame, with |y| the point's absolute local coordinates, the
nearest boundary point is x_k = a_k^2 y_k / (a_k^2 + t), where t is the root of

    F(t) = sum_k (a_k y_k / (a_k^2 + t))^2 - 1,      t > -min_k a_k^2.

F is convex and decreasing there, so Newton started left of the root climbs to it monotonically
with no overshoot; the start t0 = max_k (a_k y_k - a_k^2) is left of the root because each term
alone reaches 1 there. (The code shifts t by a_min^2 so no digits are lost near the centre.)
When a point inside lies on the plane of the shortest axis, F may have no root (the nearest point
is then off that plane) and the closed form at t = -a_min^2 is used.
"""

import numpy as np

from ..constants import DISTANCE_CUSHION_LEVEL
from ..errors import ElliMannError
from ..geometry.cushion import mannequin_cushions
from ..geometry.mesh import face_normals

NEWTON_LIMIT = 60  # iterations at most; typical convergence is under 10
_PAIRS_PER_CHUNK = 200_000  # point-triangle pairs per vectorised block (temporaries stay near 100 MB)


def ellipsoid_signed_distance(points, rotation, center, semi_axes, return_closest=False):
    """Signed distance from points (P, 3) to ellipsoids (n, ...) -> (P, n); one ellipsoid -> (P,).

    With ``return_closest`` also the nearest boundary points in world coordinates, (P, n, 3).
    """
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    rotation = np.asarray(rotation, dtype=float)
    single = rotation.ndim == 2
    rotation = rotation.reshape(-1, 3, 3)
    center = np.asarray(center, dtype=float).reshape(-1, 3)
    a = np.asarray(semi_axes, dtype=float).reshape(-1, 3)[None]  # (1, n, 3)
    local = np.einsum("pnj,njk->pnk", points[:, None, :] - center[None], rotation)  # R^T (p - c)
    y = np.abs(local)
    inside = np.sum((y / a) ** 2, axis=-1) < 1.0

    a2 = a * a
    ay = a * y
    kmin = np.argmin(a, axis=-1)  # (1, n)
    a2min = np.take_along_axis(a2, kmin[..., None], axis=-1)[..., 0]
    # Work with s = t + a_min^2 > 0 and g_k = a_k^2 - a_min^2 >= 0, so that a_k^2 + t = g_k + s is
    # never a small difference of large numbers (points near a centre would lose digits).
    g = a2 - a2min[..., None]
    floor = 1e-12 * a2min
    s = np.maximum(np.max(ay - g, axis=-1), floor)
    hi = np.where(inside, a2min, a2min + np.sqrt(a2.max(axis=-1)) * np.linalg.norm(y, axis=-1))

    def f(s):
        return np.sum((ay / (g + s[..., None])) ** 2, axis=-1) - 1.0

    # F < 0 at the start means no root right of -a_min^2 when the start is that floor; elsewhere it
    # only means the start is the root up to rounding.
    degenerate = (s <= floor) & (f(s) < 0.0)
    for _ in range(NEWTON_LIMIT):
        denom = g + s[..., None]
        ratio = ay / denom
        value = np.sum(ratio * ratio, axis=-1) - 1.0
        slope = -2.0 * np.sum(ratio * ratio / denom, axis=-1)
        step = np.where(degenerate | (slope == 0.0), 0.0, -value / np.where(slope == 0.0, 1.0, slope))
        s_new = np.minimum(s + np.maximum(step, 0.0), np.maximum(hi, s))
        done = np.all(np.abs(s_new - s) <= 1e-15 * s)
        s = s_new
        if done:
            break

    x = a2 * y / (g + s[..., None])
    if np.any(degenerate):
        # Nearest point off the shortest axis' plane: the other coordinates from t = -a_min^2,
        # the shortest one from the ellipsoid equation.
        # An axis as short as the shortest has y = 0 there too (else F had a pole): its x is 0.
        with np.errstate(divide="ignore", invalid="ignore"):
            x_deg = np.where(g > 0.0, a2 * y / g, 0.0)
        rest = np.sum((x_deg / a) ** 2, axis=-1)
        short = np.take_along_axis(a, kmin[..., None], axis=-1)[..., 0] * np.sqrt(np.clip(1.0 - rest, 0.0, None))
        x_deg = np.where(np.arange(3) == kmin[..., None], short[..., None], x_deg)
        x = np.where(degenerate[..., None], x_deg, x)

    distance = np.linalg.norm(y - x, axis=-1)
    signed = np.where(inside, -distance, distance)
    if single:
        signed = signed[:, 0]
    if not return_closest:
        return signed
    closest_local = np.where(local < 0.0, -x, x)
    closest = np.einsum("njk,pnk->pnj", rotation, closest_local) + center[None]
    return signed, (closest[:, 0] if single else closest)


def union_signed_distance(points, rotation, center, semi_axes, chunk=2048):
    """Signed distance to a union of ellipsoids: (distance (P,), index of the nearest ellipsoid (P,))."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    distance = np.empty(len(points))
    nearest = np.empty(len(points), dtype=int)
    for start in range(0, len(points), chunk):
        d = ellipsoid_signed_distance(points[start : start + chunk], rotation, center, semi_axes)
        d = d.reshape(len(d), -1)
        nearest[start : start + chunk] = np.argmin(d, axis=1)
        distance[start : start + chunk] = d.min(axis=1)
    return distance, nearest


def closest_points_on_triangles(points, a, b, c):
    """Nearest point of each triangle (a, b, c broadcastable (..., 3)) to each point (Ericson's regions)."""
    ab, ac, ap = b - a, c - a, points - a
    d1, d2 = _dot(ab, ap), _dot(ac, ap)
    bp = points - b
    d3, d4 = _dot(ab, bp), _dot(ac, bp)
    cp = points - c
    d5, d6 = _dot(ab, cp), _dot(ac, cp)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        # Interior (face region) by default; edge and vertex regions overwrite it below.
        denom = va + vb + vc
        v = vb / denom
        w = vc / denom
        result = a + ab * v[..., None] + ac * w[..., None]
        # Edge regions.
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
    regions = [
        ((vc <= 0) & (d1 >= 0) & (d3 <= 0), lambda: a + ab * t_ab[..., None]),
        ((vb <= 0) & (d2 >= 0) & (d6 <= 0), lambda: a + ac * t_ac[..., None]),
        ((va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0), lambda: b + (c - b) * t_bc[..., None]),
        ((d1 <= 0) & (d2 <= 0), lambda: np.broadcast_to(a, result.shape)),
        ((d3 >= 0) & (d4 <= d3), lambda: np.broadcast_to(b, result.shape)),
        ((d6 >= 0) & (d5 <= d6), lambda: np.broadcast_to(c, result.shape)),
    ]
    for mask, value in regions:  # later (vertex) regions take precedence, as in Ericson's order
        if np.any(mask):
            result = np.where(mask[..., None], value(), result)
    return result


def _dot(u, v):
    return np.einsum("...i,...i->...", u, v)


def mesh_distance(points, vertices, faces, signed=True, pairs_per_chunk=_PAIRS_PER_CHUNK):
    """Distance from points (P, 3) to a triangle mesh, exact: (distance (P,), face (P,)).

    Two levels of bounding spheres, no tree: the faces are grouped by the cell (about GROUP_FACES faces
    across) their centroid falls in. For each point every group gets a cheap bound (centre distance -+ radius);
    the exact distance to the triangles of the group with the smallest upper bound is a tighter upper bound;
    then every triangle of the groups whose lower bound does not exceed it gets its own, and the exact
    point-triangle distance is computed only for triangles whose lower bound does not exceed it. With ``signed``
    the mesh must be closed, 2-manifold and outward-wound: the sign is that of (p - q) . N with q the nearest
    point and N the angle-weighted pseudo-normal of the feature q lies on (face, edge or vertex), which
    Baerentzen and Aanaes (2005) show is exact for such meshes; negative inside.
    """
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    vertices, faces = np.asarray(vertices, dtype=float), np.asarray(faces)
    tri = vertices[faces]
    normals = _pseudo_normals(vertices, faces) if signed else None
    centroid = tri.mean(axis=1)
    radius = np.linalg.norm(tri - centroid[:, None], axis=-1).max(axis=1)
    order, first, count, centre, reach = _face_groups(centroid, radius)
    distance = np.empty(len(points))
    nearest = np.empty(len(points), dtype=int)
    step = max(1, pairs_per_chunk // max(len(centre), 1))
    for start in range(0, len(points), step):
        p = points[start : start + step]
        to_centre = _distances(p, centre)
        upper = (to_centre + reach).min(axis=1)
        # A tighter bound first: the exact distance to the faces of each point's best group (those faces are a
        # few dozen; the group bounds alone leave a shell of groups some reach thick around the nearest one).
        best = np.argmin(to_centre + reach, axis=1)
        near_rows = np.repeat(np.arange(len(p)), count[best])
        t = tri[order[_ranges(first[best], count[best])]]
        d2 = np.sum((closest_points_on_triangles(p[near_rows], t[:, 0], t[:, 1], t[:, 2]) - p[near_rows]) ** 2, axis=-1)
        upper = np.minimum(upper, np.sqrt(np.minimum.reduceat(d2, np.cumsum(count[best]) - count[best])))
        # 1e-9 slack: the expanded-square distances carry rounding error.
        rows, groups = np.nonzero(to_centre - reach <= upper[:, None] + 1e-9 * (1.0 + upper[:, None]))
        rows, cols = np.repeat(rows, count[groups]), order[_ranges(first[groups], count[groups])]
        lower = np.linalg.norm(p[rows] - centroid[cols], axis=1) - radius[cols]
        keep = lower <= upper[rows] + 1e-9 * (1.0 + upper[rows])
        rows, cols = rows[keep], cols[keep]
        found_distance, found_face = np.empty(len(p)), np.empty(len(p), dtype=int)
        for lo, hi in _batches(np.bincount(rows, minlength=len(p)), pairs_per_chunk):
            part = slice(*np.searchsorted(rows, (lo, hi)))  # rows ascend: np.nonzero's order, kept
            r, c = rows[part], cols[part]
            t = tri[c]
            closest = closest_points_on_triangles(p[r], t[:, 0], t[:, 1], t[:, 2])
            d2 = np.sum((closest - p[r]) ** 2, axis=-1)
            order_here = np.lexsort((d2, r))  # per point (row), smallest distance first
            best = order_here[np.r_[True, r[order_here][1:] != r[order_here][:-1]]]
            found_distance[r[best]], found_face[r[best]] = np.sqrt(d2[best]), c[best]
            if signed:
                normal = _feature_normal(normals, faces, tri[c[best]], closest[best], c[best])
                inside = np.einsum("ij,ij->i", p[r[best]] - closest[best], normal) < 0.0
                found_distance[r[best]] *= np.where(inside, -1.0, 1.0)
        distance[start : start + len(p)], nearest[start : start + len(p)] = found_distance, found_face
    return distance, nearest


GROUP_FACES = 4  # a group's cell is about this many faces across (some 16-32 on a surface: the fastest on a skin)


def _face_groups(centroid, radius):
    """Faces grouped by the cell their centroid falls in: (face order, each group's first index into it and
    count, its centre, the radius of a sphere about that centre holding its faces' bounding spheres)."""
    cell = GROUP_FACES * 2.0 * float(np.mean(radius)) if len(radius) else 1.0
    keys = np.floor(centroid / max(cell, 1e-12)).astype(np.int64)
    _, label = np.unique(keys, axis=0, return_inverse=True)
    label = label.reshape(-1)
    order = np.argsort(label, kind="stable")
    count = np.bincount(label)
    first = np.cumsum(count) - count
    centre = np.add.reduceat(centroid[order], first, axis=0) / count[:, None]
    spread = np.linalg.norm(centroid[order] - np.repeat(centre, count, axis=0), axis=1) + radius[order]
    return order, first, count, centre, np.maximum.reduceat(spread, first)


def _distances(points, centres):
    """(P, C) Euclidean distances between two point sets (the expanded square, clipped at 0)."""
    square = np.sum(points * points, axis=1)[:, None] - 2.0 * points @ centres.T + np.sum(centres * centres, axis=1)
    return np.sqrt(np.maximum(square, 0.0))


def _ranges(starts, counts):
    """The concatenated ranges start .. start + count - 1 of each pair (an index array)."""
    return np.repeat(starts - (np.cumsum(counts) - counts), counts) + np.arange(counts.sum())


def _batches(sizes, budget):
    """(lo, hi) of consecutive items whose sizes add up to about ``budget`` (at least one item each)."""
    total = np.cumsum(sizes)
    lo = 0
    while lo < len(sizes):
        hi = max(int(np.searchsorted(total, (total[lo - 1] if lo else 0) + budget, side="right")), lo + 1)
        yield lo, min(hi, len(sizes))
        lo = hi


def _pseudo_normals(vertices, faces):
    """Angle-weighted pseudo-normals: per face (F, 3), per face edge k -> k+1 (F, 3, 3), per vertex (V, 3)."""
    tri = vertices[faces]
    face = face_normals(vertices, faces)
    face /= np.linalg.norm(face, axis=1, keepdims=True)
    vertex = np.zeros_like(vertices)
    for k in range(3):
        u = tri[:, (k + 1) % 3] - tri[:, k]
        w = tri[:, (k + 2) % 3] - tri[:, k]
        cos = np.einsum("ij,ij->i", u, w) / (np.linalg.norm(u, axis=1) * np.linalg.norm(w, axis=1))
        np.add.at(vertex, faces[:, k], np.arccos(np.clip(cos, -1.0, 1.0))[:, None] * face)
    vertex /= np.maximum(np.linalg.norm(vertex, axis=1, keepdims=True), 1e-300)
    # The twin of directed edge (a, b) is (b, a) in the neighbouring face.
    start, end = faces, np.roll(faces, -1, axis=1)
    key = start.astype(np.int64) * len(vertices) + end
    twin_key = end.astype(np.int64) * len(vertices) + start
    flat = key.ravel()
    order = np.argsort(flat)
    position = np.clip(np.searchsorted(flat[order], twin_key.ravel()), 0, len(flat) - 1)
    twin = order[position]
    if not np.array_equal(flat[twin], twin_key.ravel()):
        raise ElliMannError("mesh: a signed distance needs a closed, consistently wound 2-manifold mesh")
    edge = face[:, None, :] + face[twin // 3].reshape(len(faces), 3, 3)
    edge /= np.linalg.norm(edge, axis=-1, keepdims=True)
    return face, edge, vertex


def _feature_normal(normals, faces, tri, closest, face_index):
    """Pseudo-normal of the face, edge or vertex of ``tri`` on which ``closest`` lies."""
    face, edge, vertex = normals
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = np.cross(b - a, c - a)
    area = np.einsum("ij,ij->i", n, n)
    # Barycentric weight of each corner = area of the opposite sub-triangle / area.
    bary = np.stack(
        [np.einsum("ij,ij->i", np.cross(q - closest, r - closest), n) / area for q, r in ((b, c), (c, a), (a, b))],
        axis=1,
    )
    zero = bary < 1e-9
    out = face[face_index].copy()
    # One weight zero: on the edge between the other two corners (edge k runs corner k -> k+1).
    for corner, edge_k in ((0, 1), (1, 2), (2, 0)):
        on_edge = zero[:, corner] & (zero.sum(axis=1) == 1)
        out[on_edge] = edge[face_index[on_edge], edge_k]
    # Two weights zero: at the remaining corner.
    at_vertex = zero.sum(axis=1) >= 2
    corner = np.argmax(~zero, axis=1)
    out[at_vertex] = vertex[faces[face_index[at_vertex], corner[at_vertex]]]
    return out


class BodyPieces:
    """A mannequin's convex pieces, built once for repeated distance queries.

    The pieces are its ellipsoids or, with ``cushions``, one convex hull mesh per cushion pair
    (built at ``subdivisions``) plus the remaining single ellipsoids. ``names`` holds a part name
    per piece, or :func:`cushion.cushion_name` for a cushion.
    """

    def __init__(self, mannequin, cushions=False, subdivisions=DISTANCE_CUSHION_LEVEL):
        topology = mannequin.topology
        self.singles = np.array(topology.single_parts(cushions), dtype=int)
        self.frames = (
            mannequin.rotation[self.singles],
            mannequin.center[self.singles],
            mannequin.semi_axes[self.singles],
        )
        hulls = mannequin_cushions(mannequin, subdivisions) if cushions else []
        self.meshes = [(hull.vertices, hull.faces) for hull in hulls]
        self.names = [topology.names[i] for i in self.singles] + [hull.name for hull in hulls]

    def signed_distance(self, points, cutoff=np.inf):
        """(distance (P,), index into ``names`` of the nearest piece (P,)).

        Distances to cushions beyond ``cutoff`` (m) may be reported as any value >= ``cutoff``
        (see :func:`convex_mesh_signed_distance`); ellipsoid distances are always exact.
        """
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        columns = []
        if len(self.singles):
            columns.append(ellipsoid_signed_distance(points, *self.frames).reshape(len(points), -1))
        columns += [convex_mesh_signed_distance(points, v, f, cutoff)[:, None] for v, f in self.meshes]
        table = np.concatenate(columns, axis=1)
        nearest = np.argmin(table, axis=1)
        return table[np.arange(len(points)), nearest], nearest


def mannequin_signed_distance(points, mannequin, cushions=False, subdivisions=DISTANCE_CUSHION_LEVEL):
    """Signed distance from points to a mannequin's pieces (see :class:`BodyPieces`).

    Returns (distance (P,), names of the nearest pieces). Build a BodyPieces once instead when
    querying the same mannequin many times.
    """
    pieces = BodyPieces(mannequin, cushions, subdivisions)
    distance, nearest = pieces.signed_distance(points)
    return distance, [pieces.names[i] for i in nearest]


def convex_mesh_signed_distance(points, vertices, faces, cutoff=np.inf):
    """Signed distance to a closed convex, outward-wound mesh.

    Inside it is minus the distance to the nearest face plane. Outside, when the point projects
    into the face whose plane it is furthest above, that height is the distance (the projection is
    then the nearest point of the convex body); other points get the full point-triangle search,
    except those farther than ``cutoff`` from the mesh's bounding sphere, which get that (lower)
    bound: values above ``cutoff`` are only guaranteed to be at least ``cutoff``.
    """
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    vertices = np.asarray(vertices, dtype=float)
    centre = vertices.mean(axis=0)
    distance = np.linalg.norm(points - centre, axis=1) - np.linalg.norm(vertices - centre, axis=1).max()
    near = np.nonzero(~(distance > cutoff))[0]  # the far ones keep their bound (most points, for a small cutoff)
    points = points[near]
    faces = np.asarray(faces)
    tri = vertices[faces]
    normal = face_normals(vertices, faces)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    height = points @ normal.T - np.einsum("ij,ij->i", normal, tri[:, 0])  # (P, F)
    best = np.argmax(height, axis=1)
    plane = height[np.arange(len(points)), best]
    foot = points - plane[:, None] * normal[best]
    t = tri[best]
    edges = np.roll(t, -1, axis=1) - t  # edge k runs corner k -> k+1
    # Inside the face: on the inner side of all three edges (cross product along the normal).
    side = np.einsum("pkj,pj->pk", np.cross(edges, foot[:, None, :] - t), normal[best])
    projected = np.all(side >= 0.0, axis=1)
    rest = np.nonzero((plane > 0.0) & ~projected)[0]
    if len(rest):
        plane[rest], _ = mesh_distance(points[rest], vertices, faces, signed=False)
    distance[near] = plane
    return distance


def fit_statistics(distance, contact=0.005):
    """Summary of garment-to-body signed distances (m): a dict of plain floats and counts.

    ``contact`` is the band (m) within which a vertex counts as touching the body.
    """
    d = np.asarray(distance, dtype=float).ravel()
    if not len(d) or not np.all(np.isfinite(d)):
        raise ElliMannError("distance: needs at least one finite value")
    penetrating = d < 0.0
    return {
        "count": int(len(d)),
        "min": float(d.min()),
        "max": float(d.max()),
        "mean": float(d.mean()),
        "median": float(np.median(d)),
        "p05": float(np.percentile(d, 5)),
        "p95": float(np.percentile(d, 95)),
        "penetrating": int(penetrating.sum()),
        "penetrating_fraction": float(penetrating.mean()),
        "max_depth": float(max(0.0, -d.min())),
        "touching_fraction": float(np.mean(np.abs(d) <= contact)),
    }
