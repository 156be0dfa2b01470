"""Cushions: the convex hull of two ellipsoids as a closed convex triangle mesh (Section 2.3.2).

Built from support points rather than a general 3D hull: for each direction n of an icosphere,
the hull's support point is the support point of whichever ellipsoid reaches further along n.
Directions are a triangulated sphere, so the points inherit a closed, consistently wound
triangulation; where the outermost ellipsoid changes, its triangles bridge the two ellipsoids
(the flat, ruled part of the hull). A few edges of that triangulation can be reflex where the
bridge is nearly flat; they are flipped until every edge is convex.

A closed, consistently wound surface that is locally convex at every edge and whose faces all
face away from one interior point is the boundary of a convex body (it is star-shaped, so
embedded, and a closed locally convex surface is convex). That is checked on every result. Where
the bridge is long and thin (an upper arm and forearm end to end, a foot and its toes), the flips can
end locally convex but folded over themselves at a few faces: those faces and two rings around them
are rebuilt from the exact hull of their few dozen vertices. Very flat ellipsoids (axis ratios beyond
about 6:1) can fold the direction triangulation more widely; such meshes are rebuilt by an exact
incremental hull of all the points instead.
"""

import functools
from typing import NamedTuple

import numpy as np

from ..constants import CUSHION_LEVEL
from .ellipsoid import support_and_point
from .mesh import directed_edges, face_normals, highest_above_faces, icosphere, is_closed_manifold

_MAX_FLIP_ROUNDS = 200


def cushion_name(first, second):
    """Name of the cushion of the parts named ``first`` and ``second``: ``"2.a Chest + 2.b Belly"``."""
    return f"{first} + {second}"


def cushion_mesh(first, second, subdivisions=CUSHION_LEVEL):
    """Hull of two ellipsoids, each given as (rotation, center, semi_axes).

    Returns (vertices (V, 3) in world coordinates, faces (F, 3)), counter-clockwise seen from
    outside. Use :func:`to_frame` for vertices in the first ellipsoid's frame (the paper's S_o).
    """
    return cushion_meshes([(first, second)], subdivisions)[0]


def cushion_meshes(pairs, subdivisions=CUSHION_LEVEL):
    """:func:`cushion_mesh` of every (first, second) in ``pairs``: a list of (vertices, faces).

    The meshes are those of one call per pair, built faster: the pairs share one direction sphere
    and go through the support points and the edge flips together.
    """
    if not len(pairs):
        return []
    sphere = _direction_sphere(subdivisions)
    # (2, K, ...): the first and the second ellipsoid of every pair.
    rotation, center, semi_axes = (
        np.array([[pair[side][field] for pair in pairs] for side in (0, 1)], dtype=float) for field in range(3)
    )
    vertices = _hull_support_points(rotation, center, semi_axes, sphere.directions)
    interiors = 0.5 * (center[0] + center[1])
    meshes = []
    for v, faces, interior in zip(vertices, _flip_to_locally_convex(vertices, sphere), interiors):
        if faces is not None and not _faces_point_away(v, faces, interior):
            faces = _mend_fold(v, faces, interior)
        if faces is None:
            faces = convex_hull_3d(v)
        meshes.append((v, faces))
    return meshes


_FOLD_RINGS = 2  # rings of vertices around a fold whose faces are rebuilt with it


def _mend_fold(vertices, faces, interior):
    """A locally convex mesh folded over itself somewhere (a few faces face the interior point) mended: the
    faces that are not supporting planes of the points, and those within _FOLD_RINGS rings of them, replaced by
    the faces of the exact hull of their vertices that are supporting planes. Returns the faces, or None when
    the result is not the boundary of the points' hull (closed, consistently wound, a sphere, every face a
    supporting plane, facing away from ``interior``): the caller then builds the whole hull. A fold is small, so
    this is much cheaper than the whole hull (tens of vertices instead of thousands)."""
    tol = 1e-12 * (float(np.ptp(vertices, axis=0).max()) or 1.0)
    region = np.zeros(len(vertices), dtype=bool)
    region[faces[highest_above_faces(vertices, faces) > tol]] = True
    for _ in range(_FOLD_RINGS):
        region[faces[region[faces].any(axis=1)]] = True
    rebuilt = region[faces].any(axis=1)
    patch = np.unique(faces[rebuilt])
    if len(patch) < 4 or len(patch) > len(vertices) // 4:
        return None
    try:
        local = patch[convex_hull_3d(vertices[patch])]
    except ValueError:  # the patch is flat
        return None
    local = local[highest_above_faces(vertices, local) <= tol]
    kept = faces[~rebuilt]
    known = {tuple(sorted(f)) for f in kept.tolist()}
    new = np.array([f for f in local.tolist() if tuple(sorted(f)) not in known], dtype=faces.dtype).reshape(-1, 3)
    mended = np.concatenate([kept, new])
    # closed, so E = 3F/2 and the Euler characteristic of the vertices it uses is V - F/2
    if (
        not is_closed_manifold(mended)
        or len(np.unique(mended)) - len(mended) // 2 != 2
        or not _faces_point_away(vertices, mended, interior)
    ):
        return None
    return mended


def cushion_vertices(rotation, center, semi_axes, pairs, subdivisions=CUSHION_LEVEL):
    """The vertices :func:`cushion_meshes` builds the hulls of a mannequin's ``pairs`` on, each in its
    first ellipsoid's frame (as :func:`to_frame`), without the faces: (P, V, 3).

    rotation (n, 3, 3), center (n, 3), semi_axes (n, 3): one mannequin; pairs (P, 2) part indices
    (``Topology.cushion_pairs``). Vertex k lies along direction k of the level's sphere whatever
    the ellipsoids, so a cushion mesh built at that level follows new ellipsoids by rewriting its
    vertices (the Blender panel's live update); its faces may then be no longer convex.
    """
    pairs = np.asarray(pairs, dtype=int).reshape(-1, 2)
    # (2, P, ...): the first and the second ellipsoid of every pair.
    rotation, center, semi_axes = (
        np.asarray(a, dtype=float)[pairs].swapaxes(0, 1) for a in (rotation, center, semi_axes)
    )
    vertices = _hull_support_points(rotation, center, semi_axes, _direction_sphere(subdivisions).directions)
    return to_frame(vertices, rotation[0], center[0][:, None, :])


def _hull_support_points(rotation, center, semi_axes, directions):
    """(K, V, 3): along each direction, the support point of whichever of a pair's two ellipsoids
    (arrays (2, K, ...)) reaches further: the hull's own support point."""
    reach, points = support_and_point(rotation, center, semi_axes, directions)
    return np.where((reach[0] >= reach[1])[..., None], points[0], points[1])


class CushionMesh(NamedTuple):
    """The hull of a mannequin's cushion pair: part indices, :func:`cushion_name`, vertices (V, 3), faces (F, 3)."""

    first: int
    second: int
    name: str
    vertices: np.ndarray
    faces: np.ndarray


def mannequin_cushions(mannequin, subdivisions=CUSHION_LEVEL, local=False):
    """The hull of every cushion pair of ``mannequin``, in topology order, built in one batch: a list
    of :class:`CushionMesh`. Vertices are in world coordinates, or with ``local`` in the first
    ellipsoid's frame (the paper's S_o, as :func:`to_frame`).
    """
    topology = mannequin.topology
    pairs = topology.cushion_pairs
    frames = [
        tuple((mannequin.rotation[i], mannequin.center[i], mannequin.semi_axes[i]) for i in pair) for pair in pairs
    ]
    out = []
    for (i, j), (vertices, faces) in zip(pairs, cushion_meshes(frames, subdivisions)):
        if local:
            vertices = to_frame(vertices, mannequin.rotation[i], mannequin.center[i])
        out.append(CushionMesh(i, j, cushion_name(topology.names[i], topology.names[j]), vertices, faces))
    return out


# Edge slots: slot k * F + f is the edge of face f from its corner k to corner k + 1 (the rows of
# mesh.directed_edges); its far vertex is corner k + 2 of f, its twin the slot of the reverse edge.


class _DirectionSphere(NamedTuple):
    """The icosphere of support directions and its edge structure, shared by every cushion of a level."""

    directions: np.ndarray  # (V, 3)
    faces: np.ndarray  # (F, 3)
    twin: np.ndarray  # (3F,): each edge slot's twin
    edge_keys: frozenset  # undirected edges as min * (V + 1) + max


@functools.lru_cache(maxsize=8)
def _direction_sphere(subdivisions):
    directions, faces = icosphere(subdivisions)
    edges = directed_edges(faces)
    undirected = np.sort(edges, axis=1) @ np.array([len(directions) + 1, 1])
    order = np.argsort(undirected, kind="stable")  # each undirected edge twice, side by side
    twin = np.empty(len(edges), dtype=np.int64)
    twin[order[0::2]], twin[order[1::2]] = order[1::2], order[0::2]
    for array in (directions, faces, twin):
        array.flags.writeable = False  # shared by every call
    return _DirectionSphere(directions, faces, twin, frozenset(undirected.tolist()))


def _faces_point_away(vertices, faces, interior):
    normal = face_normals(vertices, faces)
    return bool(np.all(np.einsum("ij,ij->i", normal, vertices[faces[:, 0]] - interior) > 0.0))


def to_frame(vertices, rotation, center):
    """Express world vertices in a rigid frame (rotation, center): R^T (p - c)."""
    return (np.asarray(vertices) - center) @ np.asarray(rotation)


def _flip_to_locally_convex(vertices, sphere):
    """Flip reflex edges of K closed, outward-wound triangulations until every edge is convex.

    ``vertices`` (K, V, 3) start triangulated as ``sphere.faces``. Each round flips, worst first, the
    edges that are reflex at its start, skipping an edge whose face was flipped already in that round
    or whose flip would duplicate an edge. Returns K face arrays, None for a mesh still reflex after
    _MAX_FLIP_ROUNDS rounds. Flips change few faces, so the twins, the edge set and the excesses are
    kept up to date rather than recomputed, and only the excesses near a flip are computed again.
    """
    count, size = vertices.shape[:2]
    m = len(sphere.faces)
    faces = np.repeat(sphere.faces[None], count, axis=0)
    twin = np.repeat(sphere.twin[None], count, axis=0)
    edges = [set(sphere.edge_keys) for _ in range(count)]
    scale = np.ptp(vertices, axis=1).max(axis=1)
    tol = 1e-12 * np.where(scale > 0.0, scale, 1.0)
    excess = np.empty((count, 3 * m))
    _update_excess(excess, vertices, faces, twin, np.repeat(np.arange(count), 3 * m), np.tile(np.arange(3 * m), count))
    done = np.zeros(count, dtype=bool)
    active = np.arange(count)
    for _ in range(_MAX_FLIP_ROUNDS):
        mesh, slot = np.nonzero(excess[active] > tol[active, None])
        mesh = active[mesh]
        done[np.setdiff1d(active, mesh)] = True
        if not len(mesh):
            break
        a, b, c, t, d = _slot_corners(faces, twin, mesh, slot)
        starts = np.flatnonzero(np.r_[True, mesh[1:] != mesh[:-1]])  # ``mesh`` runs in ascending order
        changed_mesh, changed_slot = [], []
        for k, start, stop in zip(mesh[starts].tolist(), starts.tolist(), [*starts[1:].tolist(), len(mesh)]):
            rows = np.arange(start, stop)
            rows = rows[np.argsort(-excess[k, slot[rows]])]  # the order sorting this mesh alone would give
            changed = _flip(
                faces[k],
                twin[k],
                edges[k],
                size + 1,
                m,
                zip(*(array[rows].tolist() for array in (slot, t, a, b, c, d))),
            )
            changed_mesh += [k] * len(changed)
            changed_slot += changed
        _update_excess(
            excess, vertices, faces, twin, np.array(changed_mesh, dtype=int), np.array(changed_slot, dtype=int)
        )
        active = np.unique(mesh)
    return [f if ok else None for f, ok in zip(faces, done)]


def _slot_corners(faces, twin, mesh, slot):
    """For edge slots of the meshes ``mesh``: the edge (a, b), its far vertex c, twin slot t, and d,
    the far vertex of the twin."""
    m = faces.shape[1]
    corner, face = np.divmod(slot, m)
    t = twin[mesh, slot]
    twin_corner, twin_face = np.divmod(t, m)
    a, b, c = (faces[mesh, face, (corner + k) % 3] for k in range(3))
    return a, b, c, t, faces[mesh, twin_face, (twin_corner + 2) % 3]


def _update_excess(excess, vertices, faces, twin, mesh, slot):
    """Store how far each edge slot's far vertex d lies above the plane of its face (a, b, c), for
    slots with a < b (each undirected edge once); -inf for the others."""
    a, b, c, _, d = _slot_corners(faces, twin, mesh, slot)
    excess[mesh, slot] = -np.inf
    once = a < b
    mesh, a, b, c, d = mesh[once], a[once], b[once], c[once], d[once]
    flat = vertices.reshape(-1, 3)
    at = mesh * vertices.shape[1]  # where each mesh's vertices start in ``flat``
    # Seen from the edge's own corner a: rounded alike for every edge (ties between excesses stay ties).
    normal = face_normals(flat, np.column_stack([a + at, b + at, c + at]))
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-300)
    excess[mesh, slot[once]] = np.einsum("ij,ij->i", normal, flat[d + at] - flat[a + at])


def _flip(faces, twin, edges, key_base, m, reflex):
    """Flip one mesh's reflex edges (slot s of edge (a, b) in face f1 = (a, b, c), twin slot t in
    f2 = (b, a, d)) into (c, d), in the given order; returns the slots whose excess changed."""
    touched, changed, rows, corners = set(), [], [], []
    links = twin.tolist()  # read and written flip by flip: a list is much faster than the array
    for s, t, a, b, c, d in reflex:
        f1, f2 = s % m, t % m
        cd = c * key_base + d if c < d else d * key_base + c
        if f1 in touched or f2 in touched or cd in edges:
            continue
        s_corner, t_corner = s // m, t // m
        # Twins outside the two faces, of (b, c), (c, a), (a, d) and (d, b).
        bc, ca = links[(s_corner + 1) % 3 * m + f1], links[(s_corner + 2) % 3 * m + f1]
        ad, db = links[(t_corner + 1) % 3 * m + f2], links[(t_corner + 2) % 3 * m + f2]
        rows.append(f1)
        rows.append(f2)
        corners.append((a, d, c))  # slots f1: (a, d), m + f1: (d, c), 2m + f1: (c, a)
        corners.append((d, b, c))  # slots f2: (d, b), m + f2: (b, c), 2m + f2: (c, d)
        links[f1], links[ad] = ad, f1
        links[m + f1], links[2 * m + f2] = 2 * m + f2, m + f1
        links[2 * m + f1], links[ca] = ca, 2 * m + f1
        links[f2], links[db] = db, f2
        links[m + f2], links[bc] = bc, m + f2
        edges.discard(a * key_base + b)
        edges.add(cd)
        touched.add(f1)
        touched.add(f2)
        changed += (f1, m + f1, 2 * m + f1, f2, m + f2, 2 * m + f2, ad, bc, ca, db)
    if rows:  # no flip reads faces, so they are written once, at the end
        faces[rows] = corners
        twin[:] = links
    return changed


def convex_hull_3d(points):
    """Exact convex hull (Quickhull-style, incremental) of points in convex position: faces (F, 3).

    Every point is expected to be a hull vertex (true for support points); points within a
    relative 1e-12 of the hull are dropped from the faces. Faces wind counter-clockwise from outside.
    """
    points = np.asarray(points, dtype=float)
    scale = float(np.ptp(points, axis=0).max()) or 1.0
    eps = 1e-12 * scale
    first = int(np.argmin(points[:, 0]))
    second = int(np.argmax(np.linalg.norm(points - points[first], axis=1)))
    line = points[second] - points[first]
    off_line = np.linalg.norm(np.cross(points - points[first], line), axis=1)
    third = int(np.argmax(off_line))
    normal = np.cross(points[second] - points[first], points[third] - points[first])
    fourth = int(np.argmax(np.abs((points - points[first]) @ normal)))
    if abs((points[fourth] - points[first]) @ normal) <= eps * np.linalg.norm(normal):
        raise ValueError("points are coplanar: no closed hull")
    faces = [(first, second, third), (first, third, fourth), (first, fourth, second), (second, fourth, third)]
    if (points[fourth] - points[first]) @ normal > 0.0:
        faces = [tuple(reversed(f)) for f in faces]
    faces = np.array(faces)
    normals, offsets = _planes(points, faces)
    alive = np.ones(len(faces), dtype=bool)
    # Conflict lists: each point not yet on the hull is owned by one face it lies outside of.
    rest = np.setdiff1d(np.arange(len(points)), faces.ravel())
    owner, height = _assign(points, rest, normals, offsets, np.arange(len(faces)), eps)
    keep = owner >= 0
    rest, owner, height = rest[keep], owner[keep], height[keep]
    while len(rest):
        pick = int(np.argmax(height))
        apex, face = rest[pick], owner[pick]
        # Faces the apex sees (for points in convex position they form one patch around `face`).
        visible = np.nonzero(alive & (normals @ points[apex] - offsets > eps))[0]
        if not len(visible):
            visible = np.array([face])
        edges = directed_edges(faces[visible])
        keys = edges[:, 0].astype(np.int64) * len(points) + edges[:, 1]
        rkeys = edges[:, 1].astype(np.int64) * len(points) + edges[:, 0]
        horizon = edges[~np.isin(rkeys, keys)]
        cone = np.column_stack([horizon, np.full(len(horizon), apex)])
        alive[visible] = False
        first_new = len(faces)
        faces = np.concatenate([faces, cone])
        cone_normals, cone_offsets = _planes(points, cone)
        normals = np.concatenate([normals, cone_normals])
        offsets = np.concatenate([offsets, cone_offsets])
        alive = np.concatenate([alive, np.ones(len(cone), dtype=bool)])
        orphan = np.isin(owner, visible) & (rest != apex)
        stay = ~np.isin(owner, visible) & (rest != apex)
        new_owner, new_height = _assign(points, rest[orphan], normals, offsets, np.arange(first_new, len(faces)), eps)
        found = new_owner >= 0
        rest = np.concatenate([rest[stay], rest[orphan][found]])
        owner = np.concatenate([owner[stay], new_owner[found]])
        height = np.concatenate([height[stay], new_height[found]])
    return faces[alive]


def _planes(points, faces):
    normal = face_normals(points, faces)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    return normal, np.einsum("ij,ij->i", normal, points[faces[:, 0]])


def _assign(points, which, normals, offsets, candidates, eps):
    """Owner face (or -1) and height of each point over the candidate faces it sees best."""
    if not len(which) or not len(candidates):
        return np.full(len(which), -1), np.zeros(len(which))
    heights = points[which] @ normals[candidates].T - offsets[candidates]
    best = np.argmax(heights, axis=1)
    top = heights[np.arange(len(which)), best]
    return np.where(top > eps, candidates[best], -1), top
