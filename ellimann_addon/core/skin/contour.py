"""The zero level set of a field sampled on a grid, as one closed triangle mesh: marching cubes with a table
built here so that every mesh it makes is watertight, 2-manifold and consistently wound.

The classic tables connect the inside corners of an ambiguous face (two inside corners on a diagonal) in one
cube and separate them in its neighbour, which leaves holes. This table decides every face by one rule, the
same from both sides: inside corners join only along the cube's edges (6-connectivity), so an ambiguous face
always separates them. On each face the crossing points are then joined in segments; every crossing point lies
on two faces, so the segments close into cycles, each a fan whose diagonals cross the cube. Two cubes sharing a
face make the same segments on it, and around a crossing point the four cubes' patches close into one disk: the
result is a closed 2-manifold whatever the field (``tests/core/skin/test_skin.py`` checks it on random fields).

Corners are numbered by their offset bits (x 1, y 2, z 4); a corner is inside where the field is negative.
"""

import numpy as np

CORNERS = np.array([[(c >> 0) & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)])
EDGES = np.array([(a, a | (1 << axis)) for axis in range(3) for a in range(8) if not a & (1 << axis)])  # (12, 2)
_EDGE_OF = {tuple(sorted(e)): i for i, e in enumerate(EDGES.tolist())}


def _faces():
    """The cube's six faces: (outward normal, its four corners in order around it)."""
    faces = []
    for axis in range(3):
        u, v = [(axis + 1) % 3, (axis + 2) % 3]
        for value in (0, 1):
            ring = [(0, 0), (1, 0), (1, 1), (0, 1)]
            corners = [(value << axis) | (a << u) | (b << v) for a, b in ring]
            normal = np.zeros(3)
            normal[axis] = 1.0 if value else -1.0
            faces.append((normal, corners))
    return faces


FACES = _faces()


_FACE_EDGES = [{_EDGE_OF[tuple(sorted((ring[k], ring[(k + 1) % 4])))] for k in range(4)} for _, ring in FACES]


def _cofacial(a, b):
    return any(a in edges and b in edges for edges in _FACE_EDGES)


def _segments(inside):
    """Directed segments (edge a, edge b) of case ``inside`` (8 booleans) on every face: the inside region on
    the left seen from outside the cube, so that chaining them winds every cycle the same way."""
    midpoint = CORNERS[EDGES].mean(axis=1)
    out = []
    for normal, ring in FACES:
        edges = [_EDGE_OF[tuple(sorted((ring[k], ring[(k + 1) % 4])))] for k in range(4)]
        crossing = [e for e in edges if inside[EDGES[e, 0]] != inside[EDGES[e, 1]]]
        if not crossing:
            continue
        if len(crossing) == 2:
            pairs = [(crossing, [c for c in ring if inside[c]])]
        else:  # ambiguous: each inside corner cut off on its own
            pairs = []
            for k, corner in enumerate(ring):
                if inside[corner]:
                    pairs.append(([edges[k - 1], edges[k]], [corner]))
        for (a, b), inner in pairs:
            d = midpoint[b] - midpoint[a]
            toward = CORNERS[inner].mean(axis=0) - midpoint[a]
            out.append((a, b) if np.dot(np.cross(normal, d), toward) > 0 else (b, a))
    return out


def _triangles(case):
    """Triangles (k, 3) of cube edges for ``case`` (the bit c set when corner c is inside), wound so that their
    normals point out of the inside region."""
    inside = [(case >> c) & 1 == 1 for c in range(8)]
    following = dict(_segments(inside))
    triangles = []
    while following:
        start = min(following)
        cycle = [start]
        while following[cycle[-1]] != start:
            cycle.append(following[cycle[-1]])
        for e in cycle:
            del following[e]
        # a fan whose diagonals all cross the cube's inside: a diagonal on a face would be a second edge there,
        # beside the neighbouring cube's segment (every cycle of the 256 cases has such a pivot)
        pivot = next(
            p for p in range(len(cycle)) if not any(_cofacial(cycle[p], cycle[p - k]) for k in range(2, len(cycle) - 1))
        )
        cycle = cycle[pivot:] + cycle[:pivot]
        triangles += [(cycle[0], cycle[k + 1], cycle[k]) for k in range(1, len(cycle) - 1)]
    return np.array(triangles, dtype=np.int64).reshape(-1, 3)


def _table():
    per_case = [_triangles(case) for case in range(256)]
    counts = np.array([len(t) for t in per_case])
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    return np.concatenate(per_case), counts, starts


TRIANGLE_EDGES, TRIANGLE_COUNTS, TRIANGLE_STARTS = _table()


def marching_cubes(values, origin, spacing):
    """The surface where ``values`` (nx, ny, nz; node (i, j, k) at origin + spacing * (i, j, k)) crosses zero,
    negative inside: (vertices (V, 3), faces (F, 3), inner (V,)), wound counter-clockwise seen from outside;
    ``inner`` is the flat index of the inside node of each vertex's grid edge.

    A node exactly at zero counts as outside; a crossing point is interpolated linearly along its grid edge,
    kept a millionth of the spacing off the nodes so that no triangle is degenerate by construction.
    """
    values = np.asarray(values, dtype=float)
    nx, ny, nz = values.shape
    inside = values < 0.0
    case = np.zeros((nx - 1, ny - 1, nz - 1), dtype=np.uint8)
    for c, (dx, dy, dz) in enumerate(CORNERS):
        case |= inside[dx : nx - 1 + dx, dy : ny - 1 + dy, dz : nz - 1 + dz].astype(np.uint8) << np.uint8(c)
    cells = np.flatnonzero((case != 0) & (case != 255))
    cell_case = case.reshape(-1)[cells]
    i, j, k = np.unravel_index(cells, case.shape)
    node = (i * ny + j) * nz + k  # the cell's corner 0, as a flat node index
    corner_offset = CORNERS @ np.array([ny * nz, nz, 1])
    counts = TRIANGLE_COUNTS[cell_case]
    owner = np.repeat(np.arange(len(cells)), counts)
    within = np.arange(len(owner)) - np.repeat(np.cumsum(counts) - counts, counts)
    edge_ids = TRIANGLE_EDGES[TRIANGLE_STARTS[cell_case[owner]] + within]  # (F, 3) cube edges
    ends = node[owner][:, None, None] + corner_offset[EDGES[edge_ids]]  # (F, 3, 2) flat node ids
    keys = ends[..., 0] * values.size + ends[..., 1]  # EDGES run from the lower corner: ends[..., 0] < ends[..., 1]
    unique, faces = np.unique(keys.reshape(-1), return_inverse=True)
    a, b = unique // values.size, unique % values.size
    flat = values.reshape(-1)
    fa, fb = flat[a], flat[b]
    t = np.clip(fa / (fa - fb), 1e-6, 1.0 - 1e-6)
    pa = np.stack(np.unravel_index(a, values.shape), axis=1)
    pb = np.stack(np.unravel_index(b, values.shape), axis=1)
    vertices = np.asarray(origin, float) + spacing * (pa + t[:, None] * (pb - pa))
    return vertices, faces.reshape(-1, 3), np.where(fa < 0.0, a, b)
