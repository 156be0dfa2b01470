"""Cushions: for every cushion pair, the convex hull of its two ellipsoids as a closed mesh object."""

import bpy
import numpy as np
from bpy.props import IntProperty
from mathutils import Matrix

from ...core.cushion import DEFAULT_SUBDIVISIONS, cushion_mesh, to_frame
from ...core.errors import MannequinError
from .. import ids
from ..built import built_collection, new_cushion_object, remove_built
from ..convert import collection_to_mannequin
from ..selection import active_mannequin, part_lookup
from .common import cancel, plural


def cushion_name(first, second):
    return f"{first} + {second}"


def rigid_frame(rotation, center):
    matrix = np.eye(4)
    matrix[:3, :3], matrix[:3, 3] = rotation, center
    return Matrix(matrix.tolist())


class ELLIMANN_OT_build_cushions(bpy.types.Operator):
    """Build the convex hull of every cushion pair of the active mannequin as a closed mesh object"""

    bl_idname = ids.BUILD_CUSHIONS
    bl_label = "Build Cushions"
    bl_options = {"REGISTER", "UNDO"}

    subdivisions: IntProperty(name="Resolution", default=DEFAULT_SUBDIVISIONS, min=1, max=6,
                              description="Icosphere subdivisions of the hull's directions "
                                          "(vertices = 10 * 4^n + 2)")

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT" and active_mannequin(context) is not None

    def execute(self, context):
        collection = active_mannequin(context)
        try:
            mannequin = collection_to_mannequin(collection)
        except MannequinError as error:
            return cancel(self, f"Fix '{collection.name}' first", error.problems)
        topology = mannequin.topology
        pairs = topology.cushion_pairs
        if not pairs:
            return cancel(self, f"'{collection.name}' has no cushion pairs: set Cushion Partner on two ellipsoids")
        # Everything is computed before the scene is touched, so a failure changes nothing.
        hulls = []
        for i, j in pairs:
            first = (mannequin.rotation[i], mannequin.center[i], mannequin.semi_axes[i])
            second = (mannequin.rotation[j], mannequin.center[j], mannequin.semi_axes[j])
            vertices, faces = cushion_mesh(first, second, self.subdivisions)
            hulls.append((i, j, to_frame(vertices, first[0], first[1]), faces))
        removed = remove_built(collection, "CUSHION")
        target = built_collection(collection, "CUSHION")
        parts = part_lookup(collection)
        for i, j, local, faces in hulls:
            first, second = topology.names[i], topology.names[j]
            new_cushion_object(cushion_name(first, second), parts[first], parts[second], local, faces,
                               rigid_frame(mannequin.rotation[i], mannequin.center[i]), target)
        replaced = f", replacing {removed}" if removed else ""
        self.report({"INFO"}, f"Built {plural(len(hulls), 'cushion')} in '{target.name}'{replaced}")
        return {"FINISHED"}


classes = (ELLIMANN_OT_build_cushions,)
register, unregister = bpy.utils.register_classes_factory(classes)
