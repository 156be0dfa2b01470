"""A body as a triangle mesh: reading OBJ / PLY / STL (numpy only), its axes and units, and sections.

OBJ files are read as Blender reads them (Y up, -Z forward): a file point (x, y, z) is the scene point
(x, -z, y). ``up="z"`` takes files written in the scene's own axes (Z up, as ../shared/refmodels' bodies).
PLY (ASCII or binary little-endian) and STL (ASCII or binary) are read in their own axes (Z up, as
Blender's importers leave them). Polygons are fanned into triangles.
"""

import os
import struct

import numpy as np

from .errors import ElliMannError

MESH_EXTENSIONS = (".obj", ".ply", ".stl")
UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}
UP_AXES = ("y", "z")


class BodyMeshError(ElliMannError):
    """A body mesh file that cannot be read (one line naming the file)."""


def read_body_mesh(path, up=None, unit="m"):
    """(vertices (V, 3) in metres, Z up; faces (F, 3) int64) of an .obj / .ply / .stl file.

    ``up``: the file's up axis ("y" or "z"; default "y" for OBJ as Blender imports it, "z" for PLY/STL);
    ``unit``: the file's length unit (m, cm, mm)."""
    kind = os.path.splitext(path)[1].lower()
    if kind not in MESH_EXTENSIONS:
        raise BodyMeshError(f"{path}: a body mesh must be {', '.join(MESH_EXTENSIONS)}, got {kind or 'no extension'}")
    if unit not in UNITS:
        raise BodyMeshError(f"unit must be one of {', '.join(UNITS)}, got {unit!r}")
    if up not in (None,) + UP_AXES:
        raise BodyMeshError(f"up must be one of {', '.join(UP_AXES)}, got {up!r}")
    try:
        with open(path, "rb") as stream:
            raw = stream.read()
    except OSError as error:
        raise BodyMeshError(f"{path}: cannot read it ({error.strerror or error})") from None
    try:
        vertices, faces = {".obj": _parse_obj, ".ply": _parse_ply, ".stl": _parse_stl}[kind](raw)
    except (ValueError, IndexError, struct.error, UnicodeDecodeError) as error:
        raise BodyMeshError(f"{path}: not a readable {kind[1:].upper()} file ({error})") from None
    if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
        raise BodyMeshError(f"{path}: a face refers to a vertex that does not exist")
    if not np.all(np.isfinite(vertices)):
        raise BodyMeshError(f"{path}: holds coordinates that are not finite numbers")
    if (up or ("y" if kind == ".obj" else "z")) == "y":
        vertices = np.stack([vertices[:, 0], -vertices[:, 2], vertices[:, 1]], axis=1)
    return vertices * UNITS[unit], faces


def _fan(polygons):
    """Triangles of polygons given as lists of vertex indices (fans from each polygon's first vertex)."""
    triangles = [(p[0], p[i], p[i + 1]) for p in polygons for i in range(1, len(p) - 1)]
    return np.array(triangles, dtype=np.int64).reshape(-1, 3)


def _parse_obj(raw):
    vertices, polygons = [], []
    for line in raw.decode("utf-8", errors="replace").splitlines():
        if line.startswith("v "):
            vertices.append([float(value) for value in line.split()[1:4]])
        elif line.startswith("f "):
            items = [int(item.split("/")[0]) for item in line.split()[1:]]
            # negative indices count back from the last vertex read so far
            polygons.append([i - 1 if i > 0 else len(vertices) + i for i in items])
    return np.array(vertices, dtype=float).reshape(-1, 3), _fan(polygons)


def _parse_ply(raw):
    end = raw.find(b"end_header")
    if not raw.startswith(b"ply") or end < 0:
        raise ValueError("no PLY header")
    header = raw[:end].decode("ascii").splitlines()
    body = raw[raw.index(b"\n", end) + 1:]
    fmt = next(line.split()[1] for line in header if line.startswith("format"))
    elements, current = [], None
    for line in header:
        words = line.split()
        if words[:1] == ["element"]:
            current = [words[1], int(words[2]), []]
            elements.append(current)
        elif words[:1] == ["property"] and current is not None:
            current[2].append(words[1:])
    types = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h", "ushort": "H",
             "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I", "float": "f", "float32": "f",
             "double": "d", "float64": "d"}
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
                    polygons.append([int(v) for v in values[1:1 + int(values[0])]])
    elif fmt == "binary_little_endian":
        offset = 0
        for name, count, props in elements:
            if all(p[0] != "list" for p in props):
                record = "<" + "".join(types[p[0]] for p in props)
                size = struct.calcsize(record)
                data = np.frombuffer(body[offset:offset + size * count], dtype=np.dtype(
                    [(f"p{i}", "<" + types[p[0]]) for i, p in enumerate(props)]), count=count)
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
    return np.array(vertices or [], dtype=float).reshape(-1, 3), _fan(polygons)


def _xyz(props):
    names = [p[-1] for p in props]
    return [names.index(axis) for axis in ("x", "y", "z")]


def _parse_stl(raw):
    if raw[:5].lower() == b"solid" and b"facet" in raw[:512]:
        corners = [[float(v) for v in line.split()[1:4]] for line in raw.decode("ascii").splitlines()
                   if line.strip().startswith("vertex")]
        points = np.array(corners, dtype=float).reshape(-1, 3)
    else:
        (count,) = struct.unpack_from("<I", raw, 80)
        records = np.frombuffer(raw[84:84 + 50 * count], dtype=np.dtype(
            [("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("attribute", "<u2")]), count=count)
        points = records["corners"].reshape(-1, 3).astype(float)
    # STL repeats each corner per triangle: weld identical corners so the mesh's edges are shared
    vertices, index = np.unique(points, axis=0, return_inverse=True)
    return vertices, np.asarray(index, dtype=np.int64).reshape(-1, 3)


def boundary_edges(faces):
    """(k, 2) edges used by exactly one triangle (a closed surface has none)."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
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
    """Component label (0..c-1) of each of ``count`` nodes joined by ``pairs`` (k, 2): minimum-label
    propagation with pointer jumping (numpy only)."""
    label = np.arange(count)
    pairs = np.asarray(pairs, np.int64).reshape(-1, 2)
    while True:
        low = np.minimum(label[pairs[:, 0]], label[pairs[:, 1]])
        new = label.copy()
        np.minimum.at(new, pairs[:, 0], low)
        np.minimum.at(new, pairs[:, 1], low)
        new = new[new]
        while True:
            jumped = new[new]
            if np.array_equal(jumped, new):
                break
            new = jumped
        if np.array_equal(new, label):
            break
        label = new
    return np.unique(label, return_inverse=True)[1].reshape(-1)


def in_plane(vertices, origin, normal):
    """Vertices in a frame whose z axis is ``normal`` (unit) and whose origin is ``origin``: the plane through
    ``origin`` across ``normal`` becomes z = 0 (its section is then :func:`section_segments` at 0)."""
    normal = np.asarray(normal, float) / np.linalg.norm(normal)
    helper = np.array([0.0, 0.0, 1.0]) if abs(normal[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    first = np.cross(helper, normal)
    first /= np.linalg.norm(first)
    frame = np.stack([first, np.cross(normal, first), normal])  # rows: the new axes
    return (np.asarray(vertices, float) - origin) @ frame.T, frame
