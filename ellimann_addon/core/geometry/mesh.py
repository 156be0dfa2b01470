"""Triangle-mesh helpers in numpy: icosphere, volume, manifold and convexity checks, plane sections, file axes."""

import numpy as np

from ..errors import ElliMannError


def icosphere(subdivisions=3):
    """Unit icosphere: (vertices (V, 3), faces (F, 3) int, counter-clockwise seen from outside).

    V = :func:`icosphere_vertex_count` (10 * 4**s + 2). Built by repeated 4-to-1 subdivision of an icosahedron.
    """
    phi = (1.0 + 5.0**0.5) / 2.0
    verts = np.array(
        [
            (-1, phi, 0),
            (1, phi, 0),
            (-1, -phi, 0),
            (1, -phi, 0),
            (0, -1, phi),
            (0, 1, phi),
            (0, -1, -phi),
            (0, 1, -phi),
            (phi, 0, -1),
            (phi, 0, 1),
            (-phi, 0, -1),
            (-phi, 0, 1),
        ],
        dtype=float,
    )
    faces = np.array(
        [
            (0, 11, 5),
            (0, 5, 1),
            (0, 1, 7),
            (0, 7, 10),
            (0, 10, 11),
            (1, 5, 9),
            (5, 11, 4),
            (11, 10, 2),
            (10, 7, 6),
            (7, 1, 8),
            (3, 9, 4),
            (3, 4, 2),
            (3, 2, 6),
            (3, 6, 8),
            (3, 8, 9),
            (4, 9, 5),
            (2, 4, 11),
            (6, 2, 10),
            (8, 6, 7),
            (9, 8, 1),
        ]
    )
    verts /= np.linalg.norm(verts, axis=1, keepdims=True)
    for _ in range(int(subdivisions)):
        edges = np.sort(directed_edges(faces), axis=1)
        unique, inverse = unique_rows(edges, return_inverse=True)
        mids = verts[unique[:, 0]] + verts[unique[:, 1]]
        mids /= np.linalg.norm(mids, axis=1, keepdims=True)
        m = len(faces)
        ab, bc, ca = (inverse[:m] + len(verts), inverse[m : 2 * m] + len(verts), inverse[2 * m :] + len(verts))
        a, b, c = faces.T
        faces = np.concatenate(
            [
                np.stack([a, ab, ca], 1),
                np.stack([b, bc, ab], 1),
                np.stack([c, ca, bc], 1),
                np.stack([ab, bc, ca], 1),
            ]
        )
        verts = np.concatenate([verts, mids])
    return verts, faces


def icosphere_vertex_count(subdivisions):
    """Vertices of :func:`icosphere` at ``subdivisions``: 10 * 4**s + 2."""
    return 10 * 4 ** int(subdivisions) + 2


def icosphere_level(vertex_count):
    """The subdivision level s whose icosphere has ``vertex_count`` vertices (10 * 4**s + 2), or None.

    Meshes built on an icosphere's directions (cushions) keep its vertex count, so it tells their level.
    """
    level = 0
    while icosphere_vertex_count(level) < vertex_count:
        level += 1
    return level if icosphere_vertex_count(level) == vertex_count else None


def check_subdivision_level(name, value, allowed):
    """``value`` as an int if it is an integer icosphere level in ``allowed`` (low, high), else an
    ElliMannError naming ``name`` and the range."""
    low, high = allowed
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not low <= value <= high:
        raise ElliMannError(f"{name}: must be an integer from {low} to {high}, got {value!r}")
    return int(value)


def directed_edges(faces):
    """Every face's edges (..., 3F, 2) of faces (..., F, 3): row k * F + f runs from corner k of face f
    to corner k + 1."""
    return np.concatenate([faces[..., [0, 1]], faces[..., [1, 2]], faces[..., [2, 0]]], axis=-2)


def unique_rows(pairs, return_inverse=False, return_counts=False):
    """np.unique(pairs, axis=0, ...) of non-negative integer pairs (k, 2) (edges), through one integer a * n + b
    per pair: the same rows in the same (lexicographic) order, the same inverse (1-D) and counts, without numpy's
    sort of a structured view (several times faster on a skin's 10^5 edges)."""
    pairs = np.asarray(pairs)
    if not len(pairs) or pairs.dtype.kind not in "iu" or pairs.min() < 0:
        out = np.unique(pairs, axis=0, return_inverse=return_inverse, return_counts=return_counts)
        if return_inverse:  # 1-D whatever numpy's version (2.0.0 shaped it otherwise)
            out = (out[0], out[1].reshape(-1), *out[2:])
        return out
    n = int(pairs.max()) + 1
    codes = pairs[:, 0].astype(np.int64) * n + pairs[:, 1]
    found = np.unique(codes, return_inverse=return_inverse, return_counts=return_counts)
    first = found[0] if isinstance(found, tuple) else found
    rows = np.stack([first // n, first % n], axis=1).astype(pairs.dtype)
    if not isinstance(found, tuple):
        return rows
    return (rows, *(extra.reshape(-1) for extra in found[1:]))


def face_normals(vertices, faces):
    """Unnormalised face normals (cross products); their length is twice the face area."""
    v = vertices[faces]
    return np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])


def volume(vertices, faces):
    """Signed volume of a closed mesh (positive when faces wind counter-clockwise from outside)."""
    v = vertices[faces]
    return float(np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6.0)


def euler_characteristic(vertices, faces):
    edges = unique_rows(np.sort(directed_edges(faces), axis=1))
    return len(vertices) - len(edges) + len(faces)


def is_closed_manifold(faces):
    """Every directed edge appears once and its reverse once: closed, 2-manifold, consistently wound."""
    directed = directed_edges(faces)
    unique, counts = unique_rows(directed, return_counts=True)
    if np.any(counts != 1):
        return False
    if not len(unique):
        return True
    # each edge's reverse among them: the rows are sorted, so their codes are, and a reverse is looked up in them
    n = int(unique.max()) + 1
    codes = unique[:, 0].astype(np.int64) * n + unique[:, 1]
    reverse = unique[:, 1].astype(np.int64) * n + unique[:, 0]
    found = np.minimum(np.searchsorted(codes, reverse), len(codes) - 1)
    return bool(np.all(codes[found] == reverse))


def convexity_defect(vertices, faces):
    """Largest distance of any vertex above any face plane (0 for a convex, outward-wound mesh)."""
    return float(highest_above_faces(vertices, faces).max(initial=0.0))


def highest_above_faces(vertices, faces):
    """(F,): how far the furthest of ``vertices`` lies above each face's plane (outward normals); <= 0 where the
    plane supports them all."""
    n = face_normals(vertices, faces)
    n = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    offsets = np.einsum("ij,ij->i", n, vertices[faces[:, 0]])
    return np.concatenate(
        [
            (vertices @ n[start : start + 2048].T).max(axis=0) - offsets[start : start + 2048]
            for start in range(0, len(faces), 2048)
        ]
        or [np.zeros(0)]
    )


def plane_section_points(vertices, faces, height):
    """Points where the mesh's edges cross the plane z = height: (k, 2) x-y coordinates."""
    faces = np.asarray(faces)
    edges = directed_edges(faces)
    above = vertices[:, 2] > height
    below = vertices[:, 2] < height
    crossing = (above[edges[:, 0]] & below[edges[:, 1]]) | (below[edges[:, 0]] & above[edges[:, 1]])
    # Deduplicate only the few crossing edges (each appears in two faces), not the whole mesh.
    edges = unique_rows(np.sort(edges[crossing], axis=1))
    za, zb = vertices[edges[:, 0], 2] - height, vertices[edges[:, 1], 2] - height
    on_plane = vertices[~above & ~below, :2]
    a, b = vertices[edges[:, 0]], vertices[edges[:, 1]]
    t = (za / (za - zb))[:, None]
    return np.concatenate([a[:, :2] + t * (b[:, :2] - a[:, :2]), on_plane])


def convex_hull_2d(points):
    """Andrew's monotone chain: hull vertices (h, 2) counter-clockwise, no collinear points."""
    pts = np.asarray(points, dtype=float)
    if len(pts) < 3:
        return np.unique(pts, axis=0)
    # np.unique(pts, axis=0)'s rows (sorted by x, then y) without its sort of a structured view, and the chain
    # walked on Python floats rather than numpy scalars: the same arithmetic, some 4x faster (the neck's search
    # takes thousands of hulls)
    pts = pts[np.lexsort((pts[:, 1], pts[:, 0]))]
    pts = pts[np.r_[True, np.any(pts[1:] != pts[:-1], axis=1)]]
    if len(pts) < 3:
        return pts
    rows = pts.tolist()
    lower, upper = [], []
    for chain, order in ((lower, rows), (upper, rows[::-1])):
        for p in order:
            px, py = p
            while len(chain) >= 2:
                (ox, oy), (ax, ay) = chain[-2], chain[-1]
                if (ax - ox) * (py - oy) - (ay - oy) * (px - ox) <= 0.0:  # no left turn: drop the last
                    chain.pop()
                else:
                    break
            chain.append(p)
    return np.array(lower[:-1] + upper[:-1])


def polygon_perimeter(polygon):
    polygon = np.asarray(polygon, dtype=float)
    if len(polygon) < 2:
        return 0.0
    return float(np.linalg.norm(polygon - np.roll(polygon, -1, axis=0), axis=1).sum())


def hull_girth(points):
    """(perimeter, hull (h, 2)) of the convex hull of 2-D points (a tape round them; 0 for fewer than three)."""
    if len(points) < 3:
        return 0.0, np.zeros((0, 2))
    hull = convex_hull_2d(points)
    return (polygon_perimeter(hull) if len(hull) >= 3 else 0.0), hull


def boundary_edges(faces):
    """(k, 2) edges used by exactly one triangle (a closed surface has none)."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    unique, counts = unique_rows(edges, return_counts=True)
    return unique[counts == 1]


def section_segments(vertices, faces, height, with_edges=False):
    """The segments in which the triangles cross the plane z = height: (k, 2, 2) x-y end points, and the
    index of each segment's triangle (and, ``with_edges``, the mesh edge (k, 2) each end point lies on, as one
    integer a * V + b with a < b: segments sharing an end share its edge). A vertex on the plane counts as
    above it (a fixed tie rule)."""
    z = vertices[faces, 2] - height  # (F, 3)
    above = z >= 0.0
    count = above.sum(axis=1)
    rows = np.nonzero((count == 1) | (count == 2))[0]
    if len(rows) == 0:
        empty = (np.zeros((0, 2, 2)), rows)
        return empty + (np.zeros((0, 2), np.int64),) if with_edges else empty
    lone_above = count[rows] == 1
    # the vertex alone on its side of the plane; the segment joins the crossings of its two edges
    lone = np.argmax(above[rows] == lone_above[:, None], axis=1)
    every = np.arange(len(rows))
    tri = vertices[faces[rows]]  # (k, 3, 3)
    zr = z[rows]
    ends, keys = [], []
    for step in (1, 2):
        other = (lone + step) % 3
        a, b = tri[every, lone], tri[every, other]
        za, zb = zr[every, lone], zr[every, other]
        t = (za / (za - zb))[:, None]
        ends.append(a[:, :2] + t * (b[:, :2] - a[:, :2]))
        ia, ib = faces[rows, lone], faces[rows, other]
        keys.append(np.minimum(ia, ib) * len(vertices) + np.maximum(ia, ib))
    if with_edges:
        return np.stack(ends, axis=1), rows, np.stack(keys, axis=1)
    return np.stack(ends, axis=1), rows


def connected_labels(count, pairs):
    """Component label (0..c-1, in order of each component's smallest node) of each of ``count`` nodes joined by
    ``pairs`` (k, 2), numpy only: rounds of hooking each edge's larger root under its smaller one, then pointer
    jumping to the roots; the edges already inside one component are dropped each round."""
    parent = np.arange(count)
    pairs = np.asarray(pairs, np.int64).reshape(-1, 2)
    while len(pairs):
        first, second = parent[pairs[:, 0]], parent[pairs[:, 1]]
        apart = first != second
        pairs, first, second = pairs[apart], first[apart], second[apart]
        if not len(pairs):
            break
        high, low = np.maximum(first, second), np.minimum(first, second)
        order = np.argsort(high, kind="stable")
        roots, starts = np.unique(high[order], return_index=True)
        parent[roots] = np.minimum(parent[roots], np.minimum.reduceat(low[order], starts))
        while True:
            jumped = parent[parent]
            if np.array_equal(jumped, parent):
                break
            parent = jumped
    return np.unique(parent, return_inverse=True)[1].reshape(-1)


def in_plane(vertices, origin, normal):
    """Vertices in a frame whose z axis is ``normal`` (unit) and whose origin is ``origin``: the plane through
    ``origin`` across ``normal`` becomes z = 0 (its section is then :func:`section_segments` at 0)."""
    normal = np.asarray(normal, float) / np.linalg.norm(normal)
    helper = np.array([0.0, 0.0, 1.0]) if abs(normal[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    first = np.cross(helper, normal)
    first /= np.linalg.norm(first)
    frame = np.stack([first, np.cross(normal, first), normal])  # rows: the new axes
    return (np.asarray(vertices, float) - origin) @ frame.T, frame


# Mesh files' axes: ElliMann's scene is Z up, facing -Y; OBJ files are Y up, -Z forward, as Blender reads and
# writes them.


def to_scene_axes(vertices, up):
    """File coordinates (V, 3) in ElliMann's axes: a Y-up file's (x, y, z) is the scene's (x, -z, y)."""
    vertices = np.asarray(vertices, dtype=float).reshape(-1, 3)
    if up == "y":
        return np.stack([vertices[:, 0], -vertices[:, 2], vertices[:, 1]], axis=1)
    return vertices


def from_scene_axes(vertices, up="y"):
    """The inverse of :func:`to_scene_axes`: scene points (V, 3) as a ``up``-up file holds them."""
    vertices = np.asarray(vertices, dtype=float).reshape(-1, 3)
    if up == "y":
        return np.stack([vertices[:, 0], vertices[:, 2], -vertices[:, 1]], axis=1)
    return vertices
