"""Drape: a garment sized from the active mannequin, simulated with Blender cloth on its convex pieces or its skin."""

import contextlib

import bpy

from ....core.errors import ElliMannError, MannequinError
from ....core.pose.kinematics import require_joints
from ....core.pose.motion import clamped_motion
from ... import ids
from ...services.drape import drape
from ..base import MannequinOperator, OperatorError, has_mannequin, mannequin_or_cancel
from .props import REST

PENETRATION_WARNING = 0.01  # fraction of garment vertices inside the body worth a warning


def body_motion(mannequin, pose):
    """(core poses or None, loops) for the Drape panel's Body: None at rest; ElliMannError without joints."""
    if pose == REST:
        return None, False
    poses, _, loops = clamped_motion(pose, require_joints(mannequin))
    return poses, loops


@contextlib.contextmanager
def progress_bar(window_manager, total):
    """Blender's progress indicator from 0 to ``total`` (the cursor shows the count); yields the update
    function and ends the indicator however the block ends."""
    window_manager.progress_begin(0, total)
    try:
        yield window_manager.progress_update
    finally:
        window_manager.progress_end()


class ELLIMANN_OT_drape_garment(MannequinOperator, bpy.types.Operator):
    """Drape a garment sized from the active mannequin's measurements, on its convex pieces or its skin"""

    bl_idname = ids.DRAPE_GARMENT
    bl_label = "Drape Garment"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return hasattr(context.scene, "ellimann_drape") and has_mannequin(context, cls.OBJECT_MODE_ONLY)

    def run(self, context, collection):
        props = context.scene.ellimann_drape
        mannequin = mannequin_or_cancel(collection)
        settings = props.settings()
        try:
            motion, loop = body_motion(mannequin, props.pose)
            with progress_bar(context.window_manager, settings.frames) as update:
                result = drape(
                    mannequin, props.garment, settings, scene=context.scene, progress=update, motion=motion, loop=loop
                )
        except MannequinError as error:
            raise OperatorError(f"Cannot drape '{collection.name}'", error.problems) from error
        except ElliMannError as error:
            raise OperatorError(f"Cannot drape '{collection.name}': {error}") from error
        props.status = result.summary()
        if result.fit["penetrating_fraction"] > PENETRATION_WARNING:
            self.report(
                {"WARNING"},
                f"{result.fit['penetrating']} garment vertices ended inside the body: try more "
                "frames, a finer collider or a finer cloth",
            )
        self.report(
            {"INFO"},
            f"Baked {result.frames} frames ({result.seconds.sum():.1f} s): a {result.garment.name} "
            f"on '{collection.name}' in '{result.collection.name}': {props.status}",
        )
        return {"FINISHED"}


classes = (ELLIMANN_OT_drape_garment,)
