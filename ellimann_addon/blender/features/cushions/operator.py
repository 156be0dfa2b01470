"""Cushions: for every cushion pair, the convex hull of its two ellipsoids as a closed mesh object."""

import bpy
from bpy.props import IntProperty

from ....core.constants import CUSHION_LEVEL, CUSHION_LEVELS
from ....core.errors import MannequinError
from ... import ids
from ...services.cushions import build_cushions
from ..base import MannequinOperator, OperatorError, fix_first, mannequin_or_cancel, plural


class ELLIMANN_OT_build_cushions(MannequinOperator, bpy.types.Operator):
    """Build the convex hull of every cushion pair of the active mannequin as a closed mesh object"""

    bl_idname = ids.BUILD_CUSHIONS
    bl_label = "Build Cushions"
    bl_options = {"REGISTER", "UNDO"}

    subdivisions: IntProperty(
        name="Resolution",
        default=CUSHION_LEVEL,
        min=CUSHION_LEVELS[0],
        max=CUSHION_LEVELS[1],
        description="Icosphere subdivisions of the hull's directions (vertices = 10 * 4^n + 2)",
    )

    def run(self, context, collection):
        mannequin = mannequin_or_cancel(collection)
        with fix_first(collection):
            try:
                objects, removed = build_cushions(collection, self.subdivisions, mannequin=mannequin)
            except MannequinError as error:
                if error.problems[0].field != "cushions":
                    raise
                raise OperatorError(str(error.problems[0].message)) from error  # no cushion pairs
        replaced = f", replacing {removed}" if removed else ""
        target = objects[0].users_collection[0].name
        self.report({"INFO"}, f"Built {plural(len(objects), 'cushion')} in '{target}'{replaced}")
        return {"FINISHED"}


classes = (ELLIMANN_OT_build_cushions,)
