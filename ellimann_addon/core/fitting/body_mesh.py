"""Body meshes a Reference Mannequin is fitted in: reading OBJ files, per-vertex areas and normals, the
fingerprint of a mesh's connectivity (which bodies share a traced mesh's vertex order), closedness, and
the walls of a mesh's cavities (open mouth and eye sockets); reading a scan (.obj / .ply / .stl, its up axis and
unit) for measuring (``read_body_mesh``)."""

import os
import pathlib
import struct
import zlib
from dataclasses import dataclass

import numpy as np

from ..errors import ElliMannError
from ..geometry.mesh import is_closed_manifold, to_scene_axes, unique_rows
from ..measure.body import MESH_EXTENSIONS, UNITS, UP_AXES, check_mesh


class BodyMeshError(ElliMannError):
    """A body mesh that cannot be read or used; the message names the file."""


@dataclass(frozen=True)
class BodyMesh:
    """A closed triangle mesh (metres, ElliMann axes: +X the body's left, -Y front, Z up), named by its
    file stem. ``edges_crc``: fingerprint of the polygons' edges (see :func:`connectivity_fingerprint`);
    ``joints``: the body's skeleton, which the Reference Mannequin built from it carries."""

    name: str
    vertices: np.ndarray  # (V, 3)
    faces: np.ndarray  # (F, 3) int, 0-based triangles
    edges_crc: int = 0
    joints: np.ndarray = None  # (24, 3) its SMPL joints in the same axes (core.mannequin.joints), if it has a skeleton


def connectivity_fingerprint(polygons):
    """CRC-32 of the sorted set of undirected edges of ``polygons`` (lists of vertex indices).

    Two meshes with the same vertex order and faces have the same fingerprint, however their faces are
    ordered or where each polygon starts; a mesh whose vertices were renumbered has another. Edges of
    the polygons as given (not of a triangulation), so a quad mesh has the same fingerprint in Blender
    and in its OBJ file.
    """
    sizes = np.array([len(p) for p in polygons], dtype=np.int64)
    corners = np.concatenate([np.asarray(p, dtype=np.int64) for p in polygons]) if len(sizes) else np.zeros(0, int)
    return loop_fingerprint(corners, np.cumsum(sizes) - sizes, sizes)


def loop_fingerprint(corners, starts, sizes):
    """:func:`connectivity_fingerprint` of polygons given as Blender stores them: the corners' vertex
    indices (L,), each polygon's first corner (P,) and corner count (P,)."""
    corners = np.asarray(corners, dtype=np.int64)
    sizes = np.asarray(sizes, dtype=np.int64)
    following = np.arange(1, len(corners) + 1)
    ends = np.asarray(starts, dtype=np.int64) + sizes - 1
    following[ends] = starts  # a polygon's last corner joins its first
    edges = np.sort(np.stack([corners, corners[following]], axis=1), axis=1) if len(corners) else np.zeros((0, 2))
    edges = unique_rows(edges).astype("<i8")
    return zlib.crc32(edges.tobytes())


def triangulate(polygons):
    """Fan triangulation (F, 3) of polygons given as lists of vertex indices."""
    triangles = [(p[0], p[k], p[k + 1]) for p in polygons for k in range(1, len(p) - 1)]
    return np.array(triangles, dtype=np.int64).reshape(-1, 3)


def from_polygons(name, vertices, polygons):
    """A BodyMesh from vertices (V, 3) and polygons (vertex index lists), checked (see :func:`mesh_problem`)."""
    vertices = np.asarray(vertices, dtype=float).reshape(-1, 3)
    polygons = [list(p) for p in polygons]
    body = BodyMesh(name, vertices, triangulate(polygons), connectivity_fingerprint(polygons))
    problem = mesh_problem(body)
    if problem:
        raise BodyMeshError(f"{name}: {problem}")
    return body


def read_obj(path, up="y", unit="m"):
    """The body mesh of an OBJ file (``v`` and ``f`` lines; polygons fan-triangulated; texture and normal
    indices after '/' ignored; negative indices count from the end), named by the file's stem, in ElliMann's
    axes and metres. ``up``: the file's up axis ("y", as Blender writes OBJ, or "z"); ``unit``: its length unit.
    BodyMeshError, in one line naming the option that fixes it, for a body that is not closed or does not
    stand upright at a person's size in those axes and unit (``core.measure.body.check_mesh``)."""
    path = pathlib.Path(path)
    _check_axes(up, unit)
    vertices, polygons = _obj_polygons(path)
    vertices = to_scene_axes(vertices, up) * UNITS[unit]
    try:
        body = from_polygons(path.stem, vertices, polygons)
    except BodyMeshError as error:
        raise BodyMeshError(f"{path}: {str(error).removeprefix(path.stem + ': ')}") from None
    problem = check_mesh(body.vertices, body.faces, up, unit)
    if problem:
        raise BodyMeshError(f"{path}: {problem.removesuffix('; nothing measured')}")
    return body


def _obj_polygons(path):
    """(vertices (V, 3), polygons) of an OBJ file, as written (no check that the surface is closed)."""
    vertices, polygons = [], []
    try:
        with open(path, encoding="utf-8") as stream:
            for number, line in enumerate(stream, 1):
                if line.startswith("v "):
                    vertices.append(line.split()[1:4])
                elif line.startswith("f "):
                    items = [int(item.split("/")[0]) for item in line.split()[1:]]
                    if len(items) < 3:
                        raise BodyMeshError(f"{path}: line {number}: a face needs at least 3 vertices")
                    polygons.append([i - 1 if i > 0 else len(vertices) + i for i in items])
        vertices = np.array(vertices, dtype=float)
    except (OSError, UnicodeDecodeError) as error:
        raise BodyMeshError(f"{path}: cannot be read ({error})") from None
    except ValueError as error:
        if isinstance(error, BodyMeshError):
            raise
        raise BodyMeshError(f"{path}: is not an OBJ mesh ({error})") from None
    if vertices.ndim != 2 or vertices.shape[1] != 3 or not polygons:
        raise BodyMeshError(f"{path}: holds no triangle mesh (needs 'v x y z' and 'f a b c' lines)")
    bad = [i for p in polygons for i in p if not 0 <= i < len(vertices)]
    if bad:
        raise BodyMeshError(f"{path}: a face uses vertex {bad[0] + 1}, but the file has {len(vertices)} vertices")
    return vertices, polygons


def mesh_problem(body):
    """What keeps ``body`` from being a body to fit in ('' if nothing): non-finite coordinates, or not closed."""
    if not np.all(np.isfinite(body.vertices)):
        return "has non-finite vertex coordinates"
    if not len(body.faces) or not is_closed_manifold(body.faces):
        return (
            "is not closed (every edge must join exactly two consistently wound faces): fill its holes, "
            "or merge its duplicate vertices, before building"
        )
    return ""


def vertex_areas(vertices, faces):
    """A third of the area of the triangles around each vertex: weights that undo uneven mesh density."""
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    return np.bincount(faces.ravel(), weights=np.repeat(area / 3.0, 3), minlength=len(vertices))


def vertex_normals(vertices, faces):
    """Unit outward normals per vertex: the area-weighted mean of the normals of its triangles."""
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    weighted = np.cross(b - a, c - a)  # twice the area times the unit normal
    normals = np.zeros_like(vertices)
    for i in range(3):
        np.add.at(normals, faces[:, i], weighted)
    return normals / np.linalg.norm(normals, axis=1, keepdims=True)


def surface_walls(vertices, faces, normals, areas, kept, depth, spacing=None):
    """The body's surface moved out by ``depth`` along its ``normals``, as the points a fitted part keeps outside
    (core.fitting.inscribed.inscribed_ellipsoid's obstacles), with the area each stands for: the ``kept`` vertices
    (indices, with their ``areas``) and, if ``spacing`` (m) is given, points about that far apart on each triangle of
    kept vertices with a longer edge, so that a thin part cannot slip out between the vertices of a coarse mesh.
    A divided triangle's area is spread evenly over its points, corners included: the areas still sum to the
    kept vertices'. Without ``spacing``, or where no edge is longer, the kept vertices alone."""
    points, weights = vertices[kept] + depth * normals[kept], areas[kept]
    if spacing is None:
        return points, weights
    position = np.full(len(vertices), -1)
    position[kept] = np.arange(len(kept))
    triangles = faces[np.all(position[faces] >= 0, axis=1)]
    corners = vertices[triangles]  # (t, 3 corners, 3)
    longest = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).max(axis=1)
    divisions = np.ceil(longest / spacing).astype(int)
    weights = weights.copy()
    all_points, all_weights = [points], [weights]
    for k in np.unique(divisions[divisions > 1]):
        tri = triangles[divisions == k]
        a, b, c = (vertices[tri[:, i]] for i in range(3))
        area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
        share = area / ((k + 1) * (k + 2) // 2)  # per point of the triangle's grid
        i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
        grid = (i + j <= k) & ~(((i == 0) | (i == k)) & (j == 0)) & ~((i == 0) & (j == k))  # no corners
        bary = np.stack([k - i[grid] - j[grid], i[grid], j[grid]], axis=1) / k  # (g, 3)
        surface = np.einsum("gc,tcx->tgx", bary, vertices[tri])
        normal = np.einsum("gc,tcx->tgx", bary, normals[tri])
        length = np.linalg.norm(normal, axis=2, keepdims=True)
        # where the corners' normals cancel (a fold of the mesh) the point stays on the surface
        normal = np.divide(normal, length, out=np.zeros_like(normal), where=length > 1e-9)
        all_points.append((surface + depth * normal).reshape(-1, 3))
        all_weights.append(np.repeat(share, len(bary)))
        # the corners stand for the triangle's corner points now, not a third of it each
        np.add.at(weights, position[tri].ravel(), np.repeat(share - area / 3.0, 3))
    return np.concatenate(all_points), np.concatenate(all_weights)


def hidden_vertices(vertices, faces, normals, candidates, reach=0.1, cell=0.01):
    """Which ``candidates`` (vertex indices) cannot see out: the ray from the vertex along its normal
    meets the surface again within ``reach`` (m). On a closed body mesh these are the walls of its
    cavities (the open eye sockets and mouth of a body model without eyes and teeth), not its skin.

    Möller-Trumbore tests against the triangles registered in the cells (of a uniform grid) that
    the ray passes through, sampled every ``cell`` / 4 (triangle boxes are padded by as much).
    """
    candidates = np.asarray(candidates)
    origin, direction = vertices[candidates], normals[candidates]
    tri = vertices[faces]
    pad = cell / 4.0
    corner = vertices.min(axis=0) - reach - cell
    shape = np.ceil((vertices.max(axis=0) + reach + cell - corner) / cell).astype(int) + 1
    first = np.floor((tri.min(axis=1) - pad - corner) / cell).astype(int)
    span = np.floor((tri.max(axis=1) + pad - corner) / cell).astype(int) - first + 1
    count = span.prod(axis=1)
    owner = np.repeat(np.arange(len(tri)), count)
    k = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    offset = np.stack(
        [k // (span[owner, 1] * span[owner, 2]), (k // span[owner, 2]) % span[owner, 1], k % span[owner, 2]], axis=1
    )
    key = np.ravel_multi_index((first[owner] + offset).T, shape)
    order = np.argsort(key, kind="stable")
    key, owner = key[order], owner[order]
    # cells along each ray, then the (ray, triangle) pairs they hold, each pair once
    steps = np.arange(pad, reach + pad, pad)
    samples = origin[:, None] + steps[None, :, None] * direction[:, None]
    cells = np.ravel_multi_index(np.floor((samples - corner) / cell).astype(int).reshape(-1, 3).T, shape)
    ray = np.repeat(np.arange(len(candidates)), len(steps))
    lo, hi = np.searchsorted(key, cells, "left"), np.searchsorted(key, cells, "right")
    n = hi - lo
    ray = np.repeat(ray, n)
    hit_tri = owner[np.repeat(lo, n) + np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)]
    pairs = np.unique(ray * len(tri) + hit_tri)
    ray, t_index = pairs // len(tri), pairs % len(tri)
    a, b, c = tri[t_index, 0], tri[t_index, 1], tri[t_index, 2]
    o, d = origin[ray], direction[ray]
    edge1, edge2 = b - a, c - a
    p = np.cross(d, edge2)
    det = np.einsum("ij,ij->i", p, edge1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = o - a
        u = np.einsum("ij,ij->i", s, p) * inv
        q = np.cross(s, edge1)
        v = np.einsum("ij,ij->i", d, q) * inv
        t = np.einsum("ij,ij->i", q, edge2) * inv
    # the vertex's own triangles meet the ray at t = 0. A ray through an edge meets the surface: on a
    # symmetric mesh the midline's rays run along its edges, where the sign of u or v is rounding's.
    edge = 1e-9
    hit = (np.abs(det) > 1e-14) & (u >= -edge) & (v >= -edge) & (u + v <= 1 + edge) & (t > 1e-4) & (t < reach)
    return np.bincount(ray[hit], minlength=len(candidates)) > 0


# Scans and bodies from other tools (core.measure.body): any of OBJ / PLY / STL, their axes and units, open or
# closed. OBJ files are read as Blender reads them (Y up, -Z forward): a file point (x, y, z) is the scene
# point (x, -z, y); ``up="z"`` takes files written in the scene's own axes (as ../shared/refmodels' bodies).
# PLY (ASCII or binary little-endian) and STL (ASCII or binary) are read in their own axes (Z up, as
# Blender's importers leave them).


def read_body_mesh(path, up=None, unit="m"):
    """(vertices (V, 3) in metres, Z up; faces (F, 3) int64) of an .obj / .ply / .stl file.

    ``up``: the file's up axis ("y" or "z"; default "y" for OBJ as Blender imports it, "z" for PLY/STL);
    ``unit``: the file's length unit (m, cm, mm). BodyMeshError for a body that does not stand upright at a
    person's size in those axes and unit (``core.measure.body.check_mesh``)."""
    kind = os.path.splitext(path)[1].lower()
    if kind not in MESH_EXTENSIONS:
        raise BodyMeshError(f"{path}: a body mesh must be {', '.join(MESH_EXTENSIONS)}, got {kind or 'no extension'}")
    _check_axes(up, unit)
    up = up or ("y" if kind == ".obj" else "z")
    if kind == ".obj":
        vertices, polygons = _obj_polygons(path)
        faces = triangulate(polygons)
    else:
        try:
            with open(path, "rb") as stream:
                raw = stream.read()
        except OSError as error:
            raise BodyMeshError(f"{path}: cannot be read ({error.strerror or error})") from None
        try:
            vertices, faces = {".ply": _parse_ply, ".stl": _parse_stl}[kind](raw)
        except (ValueError, IndexError, struct.error, UnicodeDecodeError) as error:
            raise BodyMeshError(f"{path}: not a readable {kind[1:].upper()} file ({error})") from None
    if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
        raise BodyMeshError(f"{path}: a face refers to a vertex that does not exist")
    if not np.all(np.isfinite(vertices)):
        raise BodyMeshError(f"{path}: holds coordinates that are not finite numbers")
    vertices = to_scene_axes(vertices, up) * UNITS[unit]
    problem = check_mesh(vertices, faces, up, unit)
    if problem:
        raise BodyMeshError(f"{path}: {problem}")
    return vertices, faces


def _check_axes(up, unit):
    if unit not in UNITS:
        raise BodyMeshError(f"unit must be one of {', '.join(UNITS)}, got {unit!r}")
    if up not in (None,) + UP_AXES:
        raise BodyMeshError(f"up must be one of {', '.join(UP_AXES)}, got {up!r}")


def _parse_ply(raw):
    end = raw.find(b"end_header")
    if not raw.startswith(b"ply") or end < 0:
        raise ValueError("no PLY header")
    header = raw[:end].decode("ascii").splitlines()
    body = raw[raw.index(b"\n", end) + 1 :]
    fmt = next(line.split()[1] for line in header if line.startswith("format"))
    elements, current = [], None
    for line in header:
        words = line.split()
        if words[:1] == ["element"]:
            current = [words[1], int(words[2]), []]
            elements.append(current)
        elif words[:1] == ["property"] and current is not None:
            current[2].append(words[1:])
    types = {
        "char": "b",
        "int8": "b",
        "uchar": "B",
        "uint8": "B",
        "short": "h",
        "int16": "h",
        "ushort": "H",
        "uint16": "H",
        "int": "i",
        "int32": "i",
        "uint": "I",
        "uint32": "I",
        "float": "f",
        "float32": "f",
        "double": "d",
        "float64": "d",
    }
    vertices, polygons = None, []
    if fmt == "ascii":
        rows = iter(body.decode("ascii").split("\n"))
        for name, count, props in elements:
            for _ in range(count):
                values = next(rows).split()
                if name == "vertex":
                    vertices = vertices if vertices is not None else []
                    vertices.append([float(values[i]) for i in _xyz(props)])
                elif name == "face":
                    polygons.append([int(v) for v in values[1 : 1 + int(values[0])]])
    elif fmt == "binary_little_endian":
        offset = 0
        for name, count, props in elements:
            if all(p[0] != "list" for p in props):
                record = "<" + "".join(types[p[0]] for p in props)
                size = struct.calcsize(record)
                data = np.frombuffer(
                    body[offset : offset + size * count],
                    dtype=np.dtype([(f"p{i}", "<" + types[p[0]]) for i, p in enumerate(props)]),
                    count=count,
                )
                offset += size * count
                if name == "vertex":
                    vertices = [list(row) for row in zip(*(data[f"p{i}"] for i in _xyz(props)))]
                continue
            for _ in range(count):
                row = []
                for p in props:
                    if p[0] == "list":
                        (n,) = struct.unpack_from("<" + types[p[1]], body, offset)
                        offset += struct.calcsize(types[p[1]])
                        row = list(struct.unpack_from(f"<{n}{types[p[2]]}", body, offset))
                        offset += n * struct.calcsize(types[p[2]])
                    else:
                        offset += struct.calcsize(types[p[0]])
                if name == "face":
                    polygons.append(row)
    else:
        raise ValueError(f"PLY format {fmt} is not supported (ascii or binary_little_endian)")
    return np.array(vertices or [], dtype=float).reshape(-1, 3), triangulate(polygons)


def _xyz(props):
    names = [p[-1] for p in props]
    return [names.index(axis) for axis in ("x", "y", "z")]


def _parse_stl(raw):
    if raw[:5].lower() == b"solid" and b"facet" in raw[:512]:
        corners = [
            [float(v) for v in line.split()[1:4]]
            for line in raw.decode("ascii").splitlines()
            if line.strip().startswith("vertex")
        ]
        points = np.array(corners, dtype=float).reshape(-1, 3)
    else:
        (count,) = struct.unpack_from("<I", raw, 80)
        records = np.frombuffer(
            raw[84 : 84 + 50 * count],
            dtype=np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("attribute", "<u2")]),
            count=count,
        )
        points = records["corners"].reshape(-1, 3).astype(float)
    # STL repeats each corner per triangle: weld identical corners so the mesh's edges are shared
    vertices, index = np.unique(points, axis=0, return_inverse=True)
    return vertices, np.asarray(index, dtype=np.int64).reshape(-1, 3)
