"""Finding and fixing user mistakes on ellipsoid objects, and validating a whole mannequin.

The mistakes: Apply Scale/Rotation (the mesh is no longer the unit sphere), a negative scale (a
left-handed frame) and shear (a rotated child of a non-uniformly scaled parent). Each is detected,
reported by part name, and can be repaired exactly: the repaired ellipsoid is the same point set.
"""

import numpy as np

from ...core.constants import UNIT_SPHERE_LEVEL
from ...core.errors import FrameError, MannequinError, Problem
from ...core.fitting.point_fit import fit_affine
from ...core.geometry.ellipsoid import repair_matrix_world
from ...core.geometry.mesh import icosphere
from ...core.mannequin.topology import Topology
from .convert import (
    collection_to_mannequin,
    ellipsoid_frame,
    ellipsoid_objects,
    is_unit_sphere,
    mesh_vertices,
    read_part,
)

FIXABLE = ("mesh", "negative", "shear")
AFFINE_TOLERANCE = 1e-4  # relative to the mesh size: a larger residual means the mesh was edited

EXPLANATIONS = {
    "mesh": "Apply Scale/Rotation baked the transform into the mesh, so the object no longer reads as an "
    "ellipsoid. Fix Frames moves it back into the object transform.",
    "negative": "A negative scale makes a left-handed frame. Fix Frames flips that axis back; the "
    "ellipsoid stays the same shape in the same place.",
    "shear": "A non-uniformly scaled parent shears this rotated child. Fix Frames clears the parent "
    "(keeping the shape) and gives it the ellipsoid's principal axes.",
    "zero": "A zero scale flattens the ellipsoid to nothing; give every axis a positive size.",
    "matrix": "The object matrix is not an affine transform.",
}


def frame_issue(obj):
    """The FrameError that keeps an ellipsoid object from being a valid ellipsoid, or None."""
    try:
        ellipsoid_frame(obj)
    except FrameError as error:
        return error
    return None


def repaired_frame(obj):
    """(rotation, center, semi_axes) describing the same point set as the object shows.

    Raises FrameError when that cannot be recovered (a zero scale, or a mesh edited beyond a
    transform).
    """
    matrix = np.array(obj.matrix_world)
    if obj.type != "MESH":
        raise FrameError("object", f"is a {obj.type.lower()}, not a mesh", "matrix")
    if not is_unit_sphere(obj.data):
        unit, _ = icosphere(UNIT_SPHERE_LEVEL)
        vertices = mesh_vertices(obj.data)
        if len(vertices) != len(unit):
            raise FrameError(
                "mesh",
                f"has {len(vertices)} vertices, not the unit sphere's {len(unit)}: it was "
                "edited, so fit a new ellipsoid to its vertices instead",
                "mesh",
            )
        applied, residual = fit_affine(unit, vertices)
        if residual > AFFINE_TOLERANCE * max(float(np.ptp(vertices, axis=0).max()), 1e-12):
            raise FrameError(
                "mesh", "was edited beyond a scale or rotation: fit a new ellipsoid to its vertices instead", "mesh"
            )
        matrix = matrix @ applied
    negative = [i for i, s in enumerate(obj.scale) if s < 0.0]
    return repair_matrix_world(matrix, flip_axis=negative[0] if len(negative) == 1 else None)


def mannequin_problems(collection):
    """Every problem of a mannequin collection, each naming the ellipsoid: frames, topology, geometry."""
    objects = ellipsoid_objects(collection)
    if not objects:
        return [Problem("", "collection", f"'{collection.name}' holds no ElliMann ellipsoids")]
    problems = []
    for obj in objects:
        error = frame_issue(obj)
        if error is not None:
            problems.append(Problem(obj.ellimann.part_name or obj.name, error.field, f"{error} (object '{obj.name}')"))
    try:
        Topology([read_part(obj) for obj in objects])
    except MannequinError as error:
        problems += error.problems
    if not problems:
        problems = collection_to_mannequin(collection, check=False).problems()
    return problems
