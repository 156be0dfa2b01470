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
from ...services.skin import add_skin, make_exact_skin, make_skin
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
            skin, exact = None, None
            if props.skin:
                mannequin, skin, exact = self.skin_of(context, props, mannequin)
            if exact is not None:  # the pieces were refined for the skin: their m_T is the refinement's
                five = {key: exact.pieces_measured[key] for key in MEASUREMENTS}
            collection = add_mannequin(mannequin, five, cushions=props.output == "CUSHIONS")
            rig = build_rig(collection, mannequin) if mannequin.joints is not None else None
            if skin is not None:
                skin_live.remember(add_skin(collection, skin), skin)
        except ElliMannError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        on_skin = exact.skin_measured if exact is not None else None
        if exact is not None:
            warnings = list(warnings) + [
                f"exact mode on the skin missed {key}: skin {got:.2f} cm for {wanted:g} cm"
                for key, got, wanted in exact.misses()
            ]
        props.target = collection
        props.status = "; ".join(warnings)
        for warning in warnings:
            self.report({"WARNING"}, warning)
        shown = five if on_skin is None else {key: on_skin[key] for key in MEASUREMENTS}
        worst = relative_error(shown, request_of(props)).max()
        extra_values = measured if on_skin is None else on_skin
        values = measurement_line(shown) + "".join(f", {key} {extra_values[key]:.2f}" for key in extra_of(props))
        self.report(
            {"INFO"},
            f"Synthesized '{collection.name}' ({len(ellipsoid_objects(collection))} ellipsoids, "
            f"{props.mode.lower()}{', with an armature' if rig else ''}{', with a skin' if props.skin else ''}): "
            f"{'m_T' if on_skin is None else 'on the skin'} {values} cm, "
            f"max error {worst:.2f}%",
        )
        return {"FINISHED"}

    @staticmethod
    def skin_of(context, props, mannequin):
        """(pieces, core Skin, the ExactSkin or None): in exact mode the pieces refined until their skin measures the
        request (the five and the extra ones ticked), else the skin over the pieces as they are."""
        settings = settings_of(props.skin_level)
        window_manager = context.window_manager
        window_manager.progress_begin(0.0, 1.0)
        try:
            progress = lambda fraction, _message: window_manager.progress_update(fraction)  # noqa: E731
            if props.mode != "EXACT":
                return mannequin, make_skin(mannequin, settings, progress), None
            result = make_exact_skin(mannequin, settings, request_of(props), extra_of(props), progress)
            return result.mannequin, result.skin, result
        finally:
            window_manager.progress_end()


classes = (ELLIMANN_OT_synthesize_mannequin,)
