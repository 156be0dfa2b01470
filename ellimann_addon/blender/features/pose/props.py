"""The Pose feature's scene settings, ``Scene.ellimann_pose``: the rig a BVH clip's bone names come from, whether
its feet are held on the floor, and the outcome of the last pose or import."""

import bpy
from bpy.props import BoolProperty, EnumProperty, PointerProperty, StringProperty

from ....core.pose.bone_match import AUTO
from ....core.pose.rig_names import RIG_LABELS, RIG_NAME_MAPS

RIG_ITEMS = (
    (AUTO, "Automatic", "The listed rig that places most joints, or the bones' own names and hierarchy"),
    *((key, RIG_LABELS[key], f"{RIG_LABELS[key]} bone names") for key in RIG_NAME_MAPS),
)


class ELLIMANN_PG_pose(bpy.types.PropertyGroup):
    """Pose settings of a scene."""

    rig: EnumProperty(
        name="Bone Names",
        items=RIG_ITEMS,
        default=AUTO,
        description="Whose bone names a BVH clip uses (mapped onto the mannequin's SMPL joints)",
    )
    keep_on_floor: BoolProperty(
        name="Keep on Floor",
        default=False,
        description="Hold the lowest foot on the floor in every frame of a BVH clip (the root lifted or lowered)",
    )
    status: StringProperty(name="Last Pose", description="Outcome of the last pose or motion import")


classes = (ELLIMANN_PG_pose,)


def register_hooks():
    bpy.types.Scene.ellimann_pose = PointerProperty(type=ELLIMANN_PG_pose)


def unregister_hooks():
    del bpy.types.Scene.ellimann_pose
