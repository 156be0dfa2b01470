"""Invariants of a closed triangle mesh for the tests, beside core.geometry.mesh.is_closed_manifold (edges):
every vertex's triangles form one disk, and no two triangles that share no vertex cross (a uniform grid of
boxes finds the candidates, Moller-Trumbore decides)."""

import numpy as np


def vertex_manifold(faces, count):
    """True if around every vertex its triangles form one fan (closed: a single cycle of neighbours)."""
    faces = np.asarray(faces)
    # For every triangle and corner: the link edge (next, after) of that corner. A vertex is manifold when its
    # link edges form exactly one cycle.
    links = []
    for k in range(3):
        links.append(np.stack([faces[:, k], faces[:, (k + 1) % 3], faces[:, (k + 2) % 3]], axis=1))
    links = np.concatenate(links)
    order = np.argsort(links[:, 0], kind="stable")
    links = links[order]
    starts = np.searchsorted(links[:, 0], np.arange(count + 1))
    for v in range(count):
        edges = links[starts[v] : starts[v + 1], 1:]
        if len(edges) == 0:
            continue
        following = dict(zip(edges[:, 0].tolist(), edges[:, 1].tolist()))
        if len(following) != len(edges):
            return False
        node, steps = edges[0, 0], 0
        while True:
            node = following.get(node)
            steps += 1
            if node is None or steps > len(edges):
                return False
            if node == edges[0, 0]:
                break
        if steps != len(edges):
            return False
    return True


def self_intersections(vertices, faces, tolerance=1e-9):
    """Pairs of triangles sharing no vertex that cross (k, 2); an empty array for a mesh without any."""
    vertices, faces = np.asarray(vertices, float), np.asarray(faces)
    tri = vertices[faces]
    lo, hi = tri.min(axis=1), tri.max(axis=1)
    cell = np.median(hi - lo) * 2.0 + 1e-12
    first, last = np.floor(lo / cell).astype(np.int64), np.floor(hi / cell).astype(np.int64)
    # every triangle in every cell its box touches (boxes are about a cell wide: at most 8)
    entries = []
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                c = first + np.array([dx, dy, dz])
                ok = np.all(c <= last, axis=1)
                entries.append(np.c_[c[ok], np.flatnonzero(ok)])
    entries = np.concatenate(entries)
    keys = (entries[:, 0] * 73856093) ^ (entries[:, 1] * 19349663) ^ (entries[:, 2] * 83492791)
    order = np.argsort(keys, kind="stable")
    keys, owners = keys[order], entries[order, 3]
    pairs, offset = [], 1
    while offset < len(keys):  # entries ``offset`` apart in one cell (sorted: a cell's entries are contiguous)
        same = np.flatnonzero(keys[:-offset] == keys[offset:])
        if len(same) == 0:
            break
        pairs.append(np.stack([owners[same], owners[same + offset]], axis=1))
        offset += 1
    if not pairs:
        return np.zeros((0, 2), dtype=int)
    pairs = np.sort(np.concatenate(pairs), axis=1)
    codes = np.unique(pairs[:, 0] * len(faces) + pairs[:, 1])
    pairs = np.stack([codes // len(faces), codes % len(faces)], axis=1)
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    share = (faces[pairs[:, 0]][:, :, None] == faces[pairs[:, 1]][:, None, :]).any(axis=(1, 2))
    pairs = pairs[~share]
    overlap = np.all((lo[pairs[:, 0]] <= hi[pairs[:, 1]]) & (lo[pairs[:, 1]] <= hi[pairs[:, 0]]), axis=1)
    pairs = pairs[overlap]
    crossing = np.zeros(len(pairs), dtype=bool)
    for one, other in ((0, 1), (1, 0)):
        t1, t2 = tri[pairs[:, one]], tri[pairs[:, other]]
        for k in range(3):
            crossing |= _segment_hits(t1[:, k], t1[:, (k + 1) % 3], t2, tolerance)
    return pairs[crossing]


def _segment_hits(p, q, triangle, tolerance):
    """Whether segment p-q crosses the inside of each triangle (Moller-Trumbore), ends and edges excluded."""
    direction = q - p
    e1, e2 = triangle[:, 1] - triangle[:, 0], triangle[:, 2] - triangle[:, 0]
    h = np.cross(direction, e2)
    det = np.einsum("ij,ij->i", e1, h)
    ok = np.abs(det) > tolerance
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = p - triangle[:, 0]
    u = inv * np.einsum("ij,ij->i", s, h)
    qv = np.cross(s, e1)
    v = inv * np.einsum("ij,ij->i", direction, qv)
    t = inv * np.einsum("ij,ij->i", e2, qv)
    eps = 1e-9
    return ok & (u > eps) & (v > eps) & (u + v < 1 - eps) & (t > eps) & (t < 1 - eps)
