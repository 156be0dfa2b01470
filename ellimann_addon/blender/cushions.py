"""Cushion objects of a mannequin collection: one closed convex mesh per cushion pair.

Shared by the Build Cushions operator, the Synthesize panel (live updates) and the CLI writers.
"""

import numpy as np
from mathutils import Matrix

from ..core.cushion import DEFAULT_SUBDIVISIONS, cushion_mesh, to_frame
from ..core.errors import MannequinError, Problem
from .built import built_collection, new_cushion_object, remove_built
from .convert import collection_to_mannequin
from .selection import part_lookup


def cushion_name(first, second):
    return f"{first} + {second}"


def rigid_frame(rotation, center):
    matrix = np.eye(4)
    matrix[:3, :3], matrix[:3, 3] = rotation, center
    return Matrix(matrix.tolist())


def build_cushions(collection, subdivisions=DEFAULT_SUBDIVISIONS):
    """Build (or rebuild) the cushions of a mannequin collection; returns (new objects, number replaced).

    Everything is computed before the scene is touched, so a failure (MannequinError) changes nothing.
    Rebuilding removes only cushions ElliMann built before.
    """
    mannequin = collection_to_mannequin(collection)
    topology = mannequin.topology
    pairs = topology.cushion_pairs
    if not pairs:
        raise MannequinError([Problem("", "cushions", f"'{collection.name}' has no cushion pairs: "
                                                      "set Cushion Partner on two ellipsoids")])
    hulls = []
    for i, j in pairs:
        first = (mannequin.rotation[i], mannequin.center[i], mannequin.semi_axes[i])
        second = (mannequin.rotation[j], mannequin.center[j], mannequin.semi_axes[j])
        vertices, faces = cushion_mesh(first, second, subdivisions)
        hulls.append((i, j, to_frame(vertices, first[0], first[1]), faces))
    removed = remove_built(collection, "CUSHION")
    target = built_collection(collection, "CUSHION")
    parts = part_lookup(collection)
    objects = []
    for i, j, local, faces in hulls:
        first, second = topology.names[i], topology.names[j]
        objects.append(new_cushion_object(cushion_name(first, second), parts[first], parts[second], local, faces,
                                          rigid_frame(mannequin.rotation[i], mannequin.center[i]), target))
    return objects, removed
