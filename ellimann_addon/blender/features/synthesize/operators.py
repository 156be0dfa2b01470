"""The Synthesize operator: a new mannequin collection named after the request, from the scene's
``Scene.ellimann_synthesis`` (:mod:`.props`), made by the core's job (``core.job``: the mannequin, and its skin when
Skin is ticked); it becomes the target that Live updates (:mod:`.live`)."""

import bpy

from ....core.errors import ElliMannError
from ....core.job.make import make
from ....core.measurements import MEASUREMENTS, measurement_line
from ....core.synthesis.synthesize import relative_error
from ... import ids
from ...bridge.convert import ellipsoid_objects
from ...services.rig import build_rig, check_rig
from ...services.scene import add_mannequin
from ...services.skin import add_skin
from ..skin import live as skin_live
from ..skin.operator import settings_of
from .request import extra_of, job_of, request_of


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
        window_manager = context.window_manager
        window_manager.progress_begin(0.0, 1.0)
        try:
            job = job_of(props, skin=settings_of(props.skin_level, kind=props.skin_kind) if props.skin else None)
            result = make(job, lambda fraction, _message: window_manager.progress_update(fraction), bones=True)
            if result.mannequin.joints is not None:
                check_rig(result.mannequin)  # before the scene changes
            collection = add_mannequin(result.mannequin, result.five, cushions=job.request.cushions)
            rig = build_rig(collection, result.mannequin) if result.mannequin.joints is not None else None
            if result.skin is not None:
                skin_live.remember(add_skin(collection, result.skin.skin), result.skin.skin)
        except ElliMannError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        finally:
            window_manager.progress_end()
        warnings = result.warnings + ([result.missed_text()] if result.missed else [])
        props.target = collection
        props.status = "; ".join(warnings)
        for warning in warnings:
            self.report({"WARNING"}, warning)
        shown = result.shown()
        worst = relative_error({key: shown[key] for key in MEASUREMENTS}, request_of(props)).max()
        values = measurement_line(shown, [*MEASUREMENTS, *extra_of(props)])
        self.report(
            {"INFO"},
            f"Synthesized '{collection.name}' ({len(ellipsoid_objects(collection))} ellipsoids, "
            f"{props.mode.lower()}{', with an armature' if rig else ''}{', with a skin' if props.skin else ''}): "
            f"{'m_T' if result.skin is None else 'on the skin'} {values} cm, "
            f"max error {worst:.2f}%",
        )
        return {"FINISHED"}


classes = (ELLIMANN_OT_synthesize_mannequin,)
