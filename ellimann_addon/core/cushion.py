"""Cushions: the convex hull of two ellipsoids as a closed convex triangle mesh (Section 2.3.2).

Built from support points rather than a general 3D hull: for each direction n of an icosphere,
the hull's support point is the support point of whichever ellipsoid reaches further along n.
Directions are a triangulated sphere, so the points inherit a closed, consistently wound
triangulation; where the outermost ellipsoid changes, its triangles bridge the two ellipsoids
(the flat, ruled part of the hull). A few edges of that triangulation can be reflex where the
bridge is nearly flat; they are flipped until every edge is convex.

A closed, consistently wound surface that is locally convex at every edge and whose faces all
face away from one interior point is the boundary of a convex body (it is star-shaped, so
embedded, and a closed locally convex surface is convex). That is checked on every result. Very
flat ellipsoids (axis ratios beyond about 6:1) can fold the direction triangulation; such meshes
fail the check and are rebuilt by an exact incremental hull of the same points instead.
"""

import numpy as np

from .ellipsoid import support_and_point
from .mesh import directed_edges, face_normals, icosphere

DEFAULT_SUBDIVISIONS = 4  # 2,562 vertices; capsule volume within 0.5% (see tests)
_MAX_FLIP_ROUNDS = 200


def cushion_mesh(first, second, subdivisions=DEFAULT_SUBDIVISIONS):
    """Hull of two ellipsoids, each given as (rotation, center, semi_axes).

    Returns (vertices (V, 3) in world coordinates, faces (F, 3)), counter-clockwise seen from
    outside. Use :func:`to_frame` for vertices in the first ellipsoid's frame (the paper's S_o).
    """
    directions, faces = icosphere(subdivisions)
    reach, points = zip(*(support_and_point(*ellipsoid, directions) for ellipsoid in (first, second)))
    vertices = np.where((reach[0] >= reach[1])[:, None], points[0], points[1])
    interior = 0.5 * (np.asarray(first[1], float) + np.asarray(second[1], float))
    try:
        faces = make_locally_convex(vertices, faces)
    except RuntimeError:
        faces = None
    if faces is None or not _faces_point_away(vertices, faces, interior):
        faces = convex_hull_3d(vertices)
    return vertices, faces


def _faces_point_away(vertices, faces, interior):
    normal = face_normals(vertices, faces)
    return bool(np.all(np.einsum("ij,ij->i", normal, vertices[faces[:, 0]] - interior) > 0.0))


def to_frame(vertices, rotation, center):
    """Express world vertices in a rigid frame (rotation, center): R^T (p - c)."""
    return (np.asarray(vertices) - center) @ np.asarray(rotation)


def make_locally_convex(vertices, faces):
    """Flip reflex edges of a closed, outward-wound triangulation until every edge is convex."""
    faces = np.array(faces)
    scale = float(np.ptp(vertices, axis=0).max()) or 1.0
    tol = 1e-12 * scale
    for _ in range(_MAX_FLIP_ROUNDS):
        reflex = _reflex_edges(vertices, faces, tol)
        if not reflex:
            return faces
        edge_set = _edge_set(faces)
        touched = set()
        for f1, f2, a, b, c, d in reflex:
            if f1 in touched or f2 in touched or (min(c, d), max(c, d)) in edge_set:
                continue
            faces[f1] = (a, d, c)
            faces[f2] = (d, b, c)
            edge_set.discard((min(a, b), max(a, b)))
            edge_set.add((min(c, d), max(c, d)))
            touched.update((f1, f2))
    raise RuntimeError("triangulation did not become locally convex")


def _edge_set(faces):
    e = np.sort(directed_edges(faces), axis=1)
    return set(map(tuple, e.tolist()))


def _reflex_edges(vertices, faces, tol):
    """Edges (a, b) whose far vertex d lies above the plane of the face (a, b, c), worst first."""
    m = len(faces)
    directed = directed_edges(faces)
    opposite = np.concatenate([faces[:, 2], faces[:, 0], faces[:, 1]])
    owner = np.tile(np.arange(m), 3)
    key = directed[:, 0].astype(np.int64) * (len(vertices) + 1) + directed[:, 1]
    rkey = directed[:, 1].astype(np.int64) * (len(vertices) + 1) + directed[:, 0]
    order = np.argsort(key)
    twin = order[np.searchsorted(key[order], rkey)]
    first = directed[:, 0] < directed[:, 1]  # visit each undirected edge once
    idx = np.nonzero(first)[0]
    a, b, c = directed[idx, 0], directed[idx, 1], opposite[idx]
    d = opposite[twin[idx]]
    # Seen from the edge's own corner a: rounded alike for every edge (ties between excesses stay ties).
    normal = face_normals(vertices, np.column_stack([a, b, c]))
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-300)
    excess = np.einsum("ij,ij->i", normal, vertices[d] - vertices[a])
    bad = np.nonzero(excess > tol)[0]
    bad = bad[np.argsort(-excess[bad])]
    return [(owner[idx[i]], owner[twin[idx[i]]], a[i], b[i], c[i], d[i]) for i in bad.tolist()]


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
        new_owner, new_height = _assign(points, rest[orphan], normals, offsets,
                                        np.arange(first_new, len(faces)), eps)
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

