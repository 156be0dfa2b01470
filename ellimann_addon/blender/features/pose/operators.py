"""Add Armature, the standard poses and the walk cycle (one click each), and back to rest."""

import bpy
from bpy.props import EnumProperty

from ....core.errors import ElliMannError, MannequinError
from ....core.pose.standard import POSE_NAMES, WALK_FPS
from ... import ids
from ...bridge.convert import read_joints, rig_object
from ...bridge.selection import active_mannequin
from ...services.rig import build_rig, pose_standard, rest_pose
from ..base import MannequinOperator, OperatorError, mannequin_or_cancel, plural

POSE_LABELS = {"a_pose": "A-Pose", "t_pose": "T-Pose", "attention": "Attention", "sit": "Sit", "walk": "Walk"}
POSE_DESCRIPTIONS = {
    "a_pose": "The rest pose: the traced A-pose, upper arms 35 degrees from vertical",
    "t_pose": "Upper arms and forearms horizontal in the coronal plane, elbows straight",
    "attention": "Arms hanging 5 degrees from vertical, clear of the torso",
    "sit": "Hips and knees flexed 90 degrees, shins vertical, feet flat",
    "walk": f"The walk cycle as an action on the timeline: one stride per second at {WALK_FPS} fps, looping",
}
POSE_ITEMS = tuple((name, POSE_LABELS.get(name, name), POSE_DESCRIPTIONS.get(name, name)) for name in POSE_NAMES)
POSING_MODES = ("OBJECT", "POSE")


def has_joints(context):
    collection = active_mannequin(context)
    return context.mode in POSING_MODES and collection is not None and read_joints(collection) is not None


def has_rig(context):
    collection = active_mannequin(context)
    return context.mode in POSING_MODES and rig_object(collection) is not None


class ELLIMANN_OT_add_armature(MannequinOperator, bpy.types.Operator):
    """Build an armature at the active mannequin's joints (SMPL names), each piece bound to its bone, limits enforced"""

    bl_idname = ids.ADD_ARMATURE
    bl_label = "Add Armature"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT" and has_joints(context)

    def run(self, context, collection):
        mannequin = mannequin_or_cancel(collection)
        try:
            rig = build_rig(collection, mannequin)
        except MannequinError as error:
            raise OperatorError(f"Cannot rig '{collection.name}'", error.problems) from error
        except ElliMannError as error:
            raise OperatorError(f"Cannot rig '{collection.name}': {error}") from error
        context.scene.ellimann_pose.status = ""
        self.report(
            {"INFO"},
            f"Added '{rig.name}' to '{collection.name}': {plural(len(rig.data.bones), 'bone')}, "
            "every piece bound to its bone",
        )
        return {"FINISHED"}


class ELLIMANN_OT_apply_pose(MannequinOperator, bpy.types.Operator):
    """Put the active mannequin's armature in a standard pose (walk: a looping action); m_T stays the rest pose's"""

    bl_idname = ids.APPLY_POSE
    bl_label = "Apply Pose"
    bl_options = {"REGISTER", "UNDO"}
    OBJECT_MODE_ONLY = False

    pose: EnumProperty(name="Pose", items=POSE_ITEMS, default="t_pose", description="The standard pose to apply")

    @classmethod
    def poll(cls, context):
        return has_rig(context)

    def run(self, context, collection):
        rig = rig_object(collection)
        joints = read_joints(collection)
        if joints is None:
            raise OperatorError(f"Cannot pose '{collection.name}': it has no joints (rig it again: Add Armature)")
        label = POSE_LABELS.get(self.pose, self.pose)
        try:
            poses, reports, action = pose_standard(rig, joints, self.pose, context.scene, f"{collection.name} {label}")
        except ElliMannError as error:
            raise OperatorError(f"Cannot pose '{collection.name}': {error}") from error
        if action is not None:
            text = (
                f"'{collection.name}' walks: action '{action.name}', frames 1-{len(poses)} at {WALK_FPS} fps, "
                "looping (play the timeline)"
            )
        else:
            text = f"'{collection.name}' in {label}"
        for report in reports:
            self.report({"WARNING"}, f"clamped: {report}")
        status = f"{label}" + (f"; {plural(len(reports), 'joint angle')} clamped to the limits" if reports else "")
        context.scene.ellimann_pose.status = status
        self.report(
            {"INFO"},
            f"{text}; measurements stay the rest pose's"
            + (f" ({plural(len(reports), 'joint angle')} clamped)" if reports else ""),
        )
        return {"FINISHED"}


class ELLIMANN_OT_rest_pose(MannequinOperator, bpy.types.Operator):
    """Back to the rest pose (the traced A-pose): every bone at rest, no action on the armature"""

    bl_idname = ids.REST_POSE
    bl_label = "Rest Pose"
    bl_options = {"REGISTER", "UNDO"}
    OBJECT_MODE_ONLY = False

    @classmethod
    def poll(cls, context):
        return has_rig(context)

    def run(self, context, collection):
        rest_pose(rig_object(collection))
        context.scene.ellimann_pose.status = ""
        self.report({"INFO"}, f"'{collection.name}' is at rest (A-pose)")
        return {"FINISHED"}


classes = (ELLIMANN_OT_add_armature, ELLIMANN_OT_apply_pose, ELLIMANN_OT_rest_pose)
