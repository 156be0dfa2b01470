"""The reference body meshes of ../shared/refmodels: loading, per-vertex labels, mesh measurements.

All six OBJ files share one topology (same vertex order), so labels and vertex selections made on
the neutral reference body apply to every body.
"""

import json
import pathlib
from dataclasses import dataclass

import numpy as np

from ellimann_addon.core.constants import CM_PER_M, GIRTHS, MEASUREMENTS, SECTION_FRACTIONS
from ellimann_addon.core.joints import joints_from_makehuman
from ellimann_addon.core.mesh import convex_hull_2d, plane_section_points, polygon_perimeter

REFERENCE_BODY = "reference_female"
RM_BODIES = ("small_slim", "tall_slim", "small_chubby", "tall_chubby", "average")
LABELS_FILE = "reference_female_regions.json"
SKELETON_FILE = "skeleton.json"  # the bodies' joints (refmodels/README.md, "Skeleton")


@dataclass(frozen=True)
class Body:
    name: str
    vertices: np.ndarray  # (V, 3) metres, ElliMann axes
    faces: np.ndarray  # (F, 3) int, 0-based


@dataclass(frozen=True)
class Labels:
    """Per-vertex labels of the shared topology."""

    region: np.ndarray  # (V,) region name per vertex
    bone: np.ndarray  # (V,) dominant skinning bone name per vertex
    torso: np.ndarray  # (V,) bool: not an arm or hand vertex (the girth sections use these)


def load_obj(path):
    """Vertices and triangles of an OBJ file (``v x y z`` and ``f a b c`` lines, 1-based, '/' suffixes ignored)."""
    vertices, faces = [], []
    with open(path, encoding="utf-8") as stream:
        for line in stream:
            if line.startswith("v "):
                vertices.append(line.split()[1:4])
            elif line.startswith("f "):
                items = line.split()[1:]
                if len(items) != 3:
                    raise ValueError(f"{path}: only triangles are supported, got a face of {len(items)}")
                faces.append([item.split("/")[0] for item in items])
    return np.array(vertices, dtype=float), np.array(faces, dtype=np.int64) - 1


def load_body(folder, name):
    vertices, faces = load_obj(pathlib.Path(folder) / f"{name}.obj")
    return Body(name, vertices, faces)


def load_skeletons(folder):
    """{body: (24, 3) SMPL joints} of the reference bodies, from the body model's own rig (skeleton.json)."""
    data = json.loads((pathlib.Path(folder) / SKELETON_FILE).read_text(encoding="utf-8"))
    return {name: joints_from_makehuman(bones) for name, bones in data["bodies"].items()}


def load_labels(folder):
    with open(pathlib.Path(folder) / LABELS_FILE, encoding="utf-8") as stream:
        data = json.load(stream)
    region = np.array(data["region_names"])[np.array(data["labels"])]
    bone = np.array(data["bone_names"])[np.array(data["bone_labels"])]
    return Labels(region, bone, np.array(data["torso_mask"], dtype=bool))


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


def body_measurements(body, labels):
    """The body's own tailor measurements (cm), measured as ../shared/refmodels/README.md measured them.

    Girths: perimeter of the convex hull of the section of the torso-mask triangles (all three
    vertices in the torso); shoulder width: extent along X of the section of all triangles.
    """
    vertices, faces = body.vertices, body.faces
    floor = vertices[:, 2].min()
    height = vertices[:, 2].max() - floor
    torso_faces = faces[labels.torso[faces].all(axis=1)]
    out = {"He": height * CM_PER_M}
    points = plane_section_points(vertices, faces, floor + SECTION_FRACTIONS["Sh"] * height)
    out["Sh"] = float(np.ptp(points[:, 0])) * CM_PER_M
    for key in GIRTHS:
        points = plane_section_points(vertices, torso_faces, floor + SECTION_FRACTIONS[key] * height)
        out[key] = polygon_perimeter(convex_hull_2d(points)) * CM_PER_M
    return {key: float(out[key]) for key in MEASUREMENTS}


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
    offset = np.stack([k // (span[owner, 1] * span[owner, 2]), (k // span[owner, 2]) % span[owner, 1],
                       k % span[owner, 2]], axis=1)
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
    hit = ((np.abs(det) > 1e-14) & (u >= -edge) & (v >= -edge) & (u + v <= 1 + edge) & (t > 1e-4)
           & (t < reach))
    return np.bincount(ray[hit], minlength=len(candidates)) > 0
