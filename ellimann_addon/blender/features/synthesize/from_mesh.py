"""Synthesize from Mesh: measure the active body mesh and synthesize a mannequin with every measurement found
(the panel's options and reference set), in a new collection beside the body; both reported."""

import bpy
import numpy as np
from mathutils import Vector

from ....core.errors import ElliMannError
from ....core.job.make import make
from ....core.job.request import Request, check
from ....core.measure.extra import split_measurements
from ....core.measurements import MEASUREMENTS, measurement_line
from ... import ids
from ...services.rig import build_rig, check_rig
from ...services.scene import add_mannequin
from ..base import ElliMannOperator, OperatorError
from ..measure.body import is_body_mesh, measure_object, values_line
from .request import options_of, reference_of


class ELLIMANN_OT_synthesize_from_mesh(ElliMannOperator, bpy.types.Operator):
    """Measure the active body mesh and synthesize its twin: a mannequin meeting every measurement found"""

    bl_idname = ids.SYNTHESIZE_FROM_MESH
    bl_label = "Synthesize from Mesh"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return (
            context.mode == "OBJECT"
            and hasattr(context.scene, "ellimann_synthesis")
            and is_body_mesh(context.active_object)
        )

    def run(self, context):
        obj = context.active_object
        props = context.scene.ellimann_synthesis
        wm = context.window_manager
        wm.progress_begin(0, 2)
        try:
            try:
                reference = reference_of(props)
            except ElliMannError as error:
                raise OperatorError(str(error)) from None
            values, problems = measure_object(obj, reference.section_fractions)
            wm.progress_update(1)
            missing = [key for key in MEASUREMENTS if key not in values]
            if missing:
                raise OperatorError(
                    f"'{obj.name}': {problems[0] if problems else 'not measured'}; "
                    f"{', '.join(missing)} missing: cannot synthesize"
                )
            five, extra = split_measurements(values)
            try:
                job = check(Request(five, reference, extra, options_of(props)))
                result = make(job)
            except ElliMannError as error:
                raise OperatorError(str(error)) from None
            mannequin, measured = result.mannequin, result.measured
            warnings = result.warnings + ([result.missed_text()] if result.missed else [])
            # beside the body (a synthesized mannequin stands at x = 0): moved in the core, joints and all
            corners = [obj.matrix_world @ Vector(corner) for corner in obj.bound_box]
            leftmost = float(np.min(mannequin.center[:, 0] - mannequin.semi_axes.max(axis=1)))
            mannequin = mannequin.translated((max(c.x for c in corners) - leftmost + 0.1, 0.0, 0.0))
            if mannequin.joints is not None:
                check_rig(mannequin)  # before the scene changes
            collection = add_mannequin(mannequin, five, cushions=props.output == "CUSHIONS")
            if mannequin.joints is not None:
                build_rig(collection, mannequin)  # posable as a synthesized mannequin is
        finally:
            wm.progress_end()
        props.target = collection
        for line in problems + warnings:
            self.report({"WARNING"}, line)
        self.report(
            {"INFO"},
            f"'{obj.name}': {values_line(values)}; twin '{collection.name}': "
            f"{measurement_line(measured, [*MEASUREMENTS, *extra])} cm",
        )
        return {"FINISHED"}


classes = (ELLIMANN_OT_synthesize_from_mesh,)
