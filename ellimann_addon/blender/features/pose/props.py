"""The Pose feature's scene settings, ``Scene.ellimann_pose``: the rig a BVH clip's bone names come from and
the outcome of the last pose or import."""

import bpy
from bpy.props import EnumProperty, PointerProperty, StringProperty

from ....core.mannequin.skeleton import RIG_NAME_MAPS

RIG_LABELS = {"makehuman": "MakeHuman", "cmu": "CMU", "mixamo": "Mixamo"}
RIG_ITEMS = (
    ("AUTO", "Automatic", "The bone-name map that knows most of the clip's bones"),
    *((key, RIG_LABELS.get(key, key), f"{RIG_LABELS.get(key, key)} bone names") for key in RIG_NAME_MAPS),
)


class ELLIMANN_PG_pose(bpy.types.PropertyGroup):
    """Pose settings of a scene."""

    rig: EnumProperty(
        name="Bone Names",
        items=RIG_ITEMS,
        default="AUTO",
        description="Whose bone names a BVH clip uses (mapped onto the mannequin's SMPL joints)",
    )
    status: StringProperty(name="Last Pose", description="Outcome of the last pose or motion import")


classes = (ELLIMANN_PG_pose,)


def register_hooks():
    bpy.types.Scene.ellimann_pose = PointerProperty(type=ELLIMANN_PG_pose)


def unregister_hooks():
    del bpy.types.Scene.ellimann_pose
