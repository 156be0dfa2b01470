"""The reference body meshes of ../shared/refmodels: per-vertex labels and mesh measurements (the meshes
are read by core.fitting.body_mesh.read_obj).

All six OBJ files share one topology (same vertex order), so labels and vertex selections made on
the neutral reference body apply to every body.
"""

import dataclasses
import json
import pathlib
from dataclasses import dataclass

import numpy as np

from ellimann_addon.core.constants import CM_PER_M, GIRTHS, SECTION_FRACTIONS
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry.mesh import convex_hull_2d, plane_section_points, polygon_perimeter
from ellimann_addon.core.mannequin.joints import joints_from_makehuman
from ellimann_addon.core.measure.body import measure_body_mesh
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS

REFERENCE_BODY = "reference_female"
RM_BODIES = ("small_slim", "tall_slim", "small_chubby", "tall_chubby", "average")
LABELS_FILE = "reference_female_regions.json"
SKELETON_FILE = "skeleton.json"  # the bodies' joints (refmodels/README.md, "Skeleton")


@dataclass(frozen=True)
class Labels:
    """Per-vertex labels of the shared topology."""

    region: np.ndarray  # (V,) region name per vertex
    bone: np.ndarray  # (V,) dominant skinning bone name per vertex
    torso: np.ndarray  # (V,) bool: not an arm or hand vertex (the girth sections use these)


def load_skeletons(folder):
    """{body: (24, 3) SMPL joints} of the reference bodies, from the body model's own rig (skeleton.json)."""
    data = json.loads((pathlib.Path(folder) / SKELETON_FILE).read_text(encoding="utf-8"))
    return {name: joints_from_makehuman(bones) for name, bones in data["bodies"].items()}


def read_bodies(folder, names):
    """{name: BodyMesh} of the bodies ``names`` of a refmodels folder (Z up), each with its own joints
    (:func:`load_skeletons`), as the builder gives them to the Reference Mannequins."""
    skeletons = load_skeletons(folder)
    return {
        name: dataclasses.replace(read_obj(pathlib.Path(folder) / f"{name}.obj", up="z"), joints=skeletons[name])
        for name in names
    }


def load_labels(folder):
    with open(pathlib.Path(folder) / LABELS_FILE, encoding="utf-8") as stream:
        data = json.load(stream)
    region = np.array(data["region_names"])[np.array(data["labels"])]
    bone = np.array(data["bone_names"])[np.array(data["bone_labels"])]
    return Labels(region, bone, np.array(data["torso_mask"], dtype=bool))


def body_measurements(body, labels, fractions=SECTION_FRACTIONS):
    """The body's own tailor measurements (cm), measured as ../shared/refmodels/README.md measured them
    (at the section heights ``fractions``: the male bodies' README gives theirs).

    Girths: perimeter of the convex hull of the section of the torso-mask triangles (all three
    vertices in the torso); shoulder width: extent along X of the section of all triangles.
    """
    vertices, faces = body.vertices, body.faces
    floor = vertices[:, 2].min()
    height = vertices[:, 2].max() - floor
    torso_faces = faces[labels.torso[faces].all(axis=1)]
    out = {"He": height * CM_PER_M}
    points = plane_section_points(vertices, faces, floor + fractions["Sh"] * height)
    out["Sh"] = float(np.ptp(points[:, 0])) * CM_PER_M
    for key in GIRTHS:
        points = plane_section_points(vertices, torso_faces, floor + fractions[key] * height)
        out[key] = polygon_perimeter(convex_hull_2d(points)) * CM_PER_M
    return {key: float(out[key]) for key in MEASUREMENTS}


def body_requests(build_set, labels, names=None):
    """{body: (five {He..Hi: cm}, six {extra measurement: cm})} of a set's bodies (``names``, default all six;
    ``labels``: load_labels of the neutral body's folder, the topology every body shares): the five as the README
    measures them (body_measurements, at the set's section heights), the six extra ones as the body-mesh measurer
    takes them (core.measure.body): what a twin of each body is asked."""
    out = {}
    for name in names or (build_set.reference_body, *RM_BODIES):
        body = read_obj(build_set.refmodels / f"{name}.obj", up="z")
        five = body_measurements(body, labels, build_set.fractions)
        measured = measure_body_mesh(body.vertices, body.faces, build_set.fractions).values
        out[name] = (five, {key: measured[key] for key in EXTRA_MEASUREMENTS if key in measured})
    return out
