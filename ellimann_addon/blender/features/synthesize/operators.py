"""The Synthesize operator: a new mannequin collection named after the request, from the scene's
``Scene.ellimann_synthesis`` (:mod:`.props`); it becomes the target that Live updates (:mod:`.live`)."""

import bpy

from ....core.constants import MEASUREMENTS
from ....core.errors import ElliMannError
from ....core.measure.tailor import measurement_line
from ....core.synthesis.synthesize import relative_error
from ... import ids
from ...bridge.convert import ellipsoid_objects
from ...services.rig import build_rig, check_rig
from ...services.scene import add_mannequin
from ...services.skin import add_skin, make_skin
from ..skin import live as skin_live
from ..skin.operator import settings_of
from .request import extra_of, request_of, synthesize_request


class ELLIMANN_OT_synthesize_mannequin(bpy.types.Operator):
    """Build a new mannequin from the five measurements (segmented IDW over the RMs), rigged if they have joints"""

    bl_idname = ids.SYNTHESIZE_MANNEQUIN
    bl_label = "Synthesize"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.scene is not None and hasattr(context.scene, "ellimann_synthesis")

    def execute(self, context):
        props = context.scene.ellimann_synthesis
        try:
            mannequin, measured, warnings = synthesize_request(props, measure_extra=False)
            five = {key: measured[key] for key in MEASUREMENTS}
            if mannequin.joints is not None:
                check_rig(mannequin)  # before the scene changes
            skin = make_skin(mannequin, settings_of(props.skin_level)) if props.skin else None
            collection = add_mannequin(mannequin, five, cushions=props.output == "CUSHIONS")
            rig = build_rig(collection, mannequin) if mannequin.joints is not None else None
            if skin is not None:
                skin_live.remember(add_skin(collection, skin), skin)
        except ElliMannError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        props.target = collection
        props.status = "; ".join(warnings)
        for warning in warnings:
            self.report({"WARNING"}, warning)
        worst = relative_error(five, request_of(props)).max()
        values = measurement_line(five) + "".join(f", {key} {measured[key]:.2f}" for key in extra_of(props))
        self.report(
            {"INFO"},
            f"Synthesized '{collection.name}' ({len(ellipsoid_objects(collection))} ellipsoids, "
            f"{props.mode.lower()}{', with an armature' if rig else ''}{', with a skin' if props.skin else ''}): "
            f"m_T {values} cm, "
            f"max error {worst:.2f}%",
        )
        return {"FINISHED"}


classes = (ELLIMANN_OT_synthesize_mannequin,)
