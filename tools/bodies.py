"""The reference body meshes of ../shared/refmodels: loading, per-vertex labels, mesh measurements.

All six OBJ files share one topology (same vertex order), so labels and vertex selections made on
the neutral reference body apply to every body.
"""

import json
import pathlib
from dataclasses import dataclass

import numpy as np

from ellimann_addon.core.constants import CM_PER_M, GIRTHS, MEASUREMENTS, SECTION_FRACTIONS
from ellimann_addon.core.mesh import convex_hull_2d, plane_section_points, polygon_perimeter

REFERENCE_BODY = "reference_female"
RM_BODIES = ("small_slim", "tall_slim", "small_chubby", "tall_chubby", "average")
LABELS_FILE = "reference_female_regions.json"


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


def body_measurements(body, labels):
    """The body's own tailor measurements (cm), measured as DESIGN.md says.

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
