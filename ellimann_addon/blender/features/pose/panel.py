"""The Pose sub-panel of the ElliMann sidebar tab: the armature, the standard poses, the walk, BVH motion."""

import math

import bpy

from ... import ids
from ...bridge.convert import read_joints, rig_object
from ...bridge.selection import active_mannequin
from ...services.rig import CONSTRAINT_NAME
from ..base import SubPanel
from .operators import POSE_ITEMS


class ELLIMANN_PT_pose(SubPanel, bpy.types.Panel):
    """Pose the active mannequin: standard poses, the walk cycle, BVH clips"""

    bl_idname = ids.PANEL_POSE
    bl_label = "Pose"
    bl_order = ids.POSE_ORDER

    @classmethod
    def poll(cls, context):
        return hasattr(context.scene, "ellimann_pose")

    def draw(self, context):
        layout = self.layout
        collection = active_mannequin(context)
        if collection is None:
            layout.label(text="No active mannequin")
            return
        rig = rig_object(collection)
        if read_joints(collection) is None:
            layout.label(text="No joints: an older mannequin", icon="INFO")
        layout.operator(ids.ADD_ARMATURE, icon="ARMATURE_DATA", text="Rebuild Armature" if rig else "Add Armature")
        if rig is None:
            return
        grid = layout.grid_flow(columns=2, align=True)
        for value, label, _ in POSE_ITEMS:
            grid.operator(ids.APPLY_POSE, text=label).pose = value
        layout.operator(ids.REST_POSE, icon="LOOP_BACK")
        draw_limits(layout, context, rig)
        props = context.scene.ellimann_pose
        row = layout.row(align=True)
        row.prop(props, "rig", text="")
        row.operator(ids.IMPORT_BVH, icon="IMPORT", text="Import BVH")
        layout.prop(props, "keep_on_floor")
        if props.status:
            box = layout.box()
            for number, line in enumerate(props.status.splitlines()):
                box.label(text=line, icon="INFO" if number == 0 else "BLANK1")
        layout.label(text="Measurements are the rest pose's", icon="INFO")


def draw_limits(layout, context, rig):
    """The active bone's rotation limits (its Limit Rotation constraint), in degrees about the bone's own axes."""
    bone = getattr(context, "active_pose_bone", None)
    if bone is None or bone.id_data != rig:
        return
    constraint = bone.constraints.get(CONSTRAINT_NAME)
    box = layout.box()
    if constraint is None:
        box.label(text=f"{bone.name}: free (no limits)")
        return
    box.label(text=f"{bone.name} limits (degrees, bone axes, {constraint.euler_order})")
    for axis in "xyz":
        if not getattr(constraint, f"use_limit_{axis}"):
            box.label(text=f"{axis.upper()}: free")
            continue
        low, high = (math.degrees(getattr(constraint, f"{end}_{axis}")) for end in ("min", "max"))
        span = "locked" if abs(high - low) < 1e-6 else f"{low:.0f} to {high:.0f}"
        box.label(text=f"{axis.upper()}: {span}")


classes = (ELLIMANN_PT_pose,)
