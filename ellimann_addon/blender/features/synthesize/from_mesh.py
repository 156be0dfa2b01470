"""Synthesize from Mesh: measure the active body mesh and synthesize a mannequin with every measurement found
(the panel's options and reference set), in a new collection beside the body; both reported."""

import bpy

from ....core.constants import MEASUREMENTS
from ....core.errors import ElliMannError
from ....core.measure import measurement_line
from ... import ids
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
        return (context.mode == "OBJECT" and hasattr(context.scene, "ellimann_synthesis")
                and is_body_mesh(context.active_object))

    def run(self, context):
        from ....core.refine_extra import synthesize_extra

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
                raise OperatorError(f"'{obj.name}': {problems[0] if problems else 'not measured'}; "
                                    f"{', '.join(missing)} missing: cannot synthesize")
            five = {key: values[key] for key in MEASUREMENTS}
            extra = {key: value for key, value in values.items() if key not in MEASUREMENTS}
            try:
                mannequin, measured, warnings = synthesize_extra(reference, five, extra, options_of(props))
            except ElliMannError as error:
                raise OperatorError(str(error)) from None
            collection = add_mannequin(mannequin, five, cushions=props.output == "CUSHIONS")
        finally:
            wm.progress_end()
        # beside the body: the twin's pieces are registered at x = 0
        width = float(max(v[0] for v in obj.bound_box) - min(v[0] for v in obj.bound_box)) * max(obj.scale)
        for piece in collection.all_objects:
            piece.location.x += obj.matrix_world.translation.x + width
        props.target = collection
        for line in problems + warnings:
            self.report({"WARNING"}, line)
        self.report({"INFO"}, f"'{obj.name}': {values_line(values)}; twin '{collection.name}': "
                              f"{measurement_line(measured)}"
                              + "".join(f", {key} {measured[key]:.2f}" for key in extra) + " cm")
        return {"FINISHED"}


classes = (ELLIMANN_OT_synthesize_from_mesh,)
