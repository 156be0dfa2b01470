"""Cushion objects of a mannequin collection: one closed convex mesh per cushion pair.

Shared by the Build Cushions operator, the Synthesize feature (live updates) and the CLI writers.
"""

from mathutils import Matrix

from ...core.constants import CUSHION_LEVEL
from ...core.errors import MannequinError, Problem
from ...core.geometry.cushion import mannequin_cushions
from ...core.geometry.frames import rigid_matrix
from ..bridge.built import built_collection, new_cushion_object, remove_built
from ..bridge.convert import collection_to_mannequin, rig_object
from ..bridge.selection import part_lookup
from .rig import bind_cushions


def rigid_frame(rotation, center):
    """:func:`core.geometry.frames.rigid_matrix` as a mathutils Matrix (a cushion object's matrix_world)."""
    return Matrix(rigid_matrix(rotation, center).tolist())


def build_cushions(collection, subdivisions=CUSHION_LEVEL, mannequin=None):
    """Build (or rebuild) the cushions of a mannequin collection; returns (new objects, number replaced).

    ``mannequin``: the core mannequin the collection was just made from, when the caller has it (the
    hulls are computed from it instead of the objects read back); None: read from the collection.
    Everything is computed before the scene is touched, so a failure (MannequinError) changes nothing.
    Rebuilding removes only cushions ElliMann built before. On a mannequin with an armature they are bound
    to its bones (``services.rig.bind_cushions``).
    """
    if mannequin is None:
        mannequin = collection_to_mannequin(collection)
    topology = mannequin.topology
    pairs = topology.cushion_pairs
    if not pairs:
        raise MannequinError(
            [
                Problem(
                    "", "cushions", f"'{collection.name}' has no cushion pairs: set Cushion Partner on two ellipsoids"
                )
            ]
        )
    hulls = mannequin_cushions(mannequin, subdivisions, local=True)
    removed = remove_built(collection, "CUSHION")
    target = built_collection(collection, "CUSHION")
    parts = part_lookup(collection)
    objects = []
    for hull in hulls:
        first, second = topology.names[hull.first], topology.names[hull.second]
        objects.append(
            new_cushion_object(
                hull.name,
                parts[first],
                parts[second],
                hull.vertices,
                hull.faces,
                rigid_frame(mannequin.rotation[hull.first], mannequin.center[hull.first]),
                target,
            )
        )
    if rig_object(collection) is not None and mannequin.joints is not None:  # a rigged mannequin: bind them too
        bind_cushions(collection, mannequin)
    return objects, removed
