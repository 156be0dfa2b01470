"""The Pose sub-panel of the ElliMann sidebar tab: the armature, the standard poses, the walk, BVH motion."""

import bpy

from ... import ids
from ...bridge.convert import read_joints, rig_object
from ...bridge.selection import active_mannequin
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
        props = context.scene.ellimann_pose
        row = layout.row(align=True)
        row.prop(props, "rig", text="")
        row.operator(ids.IMPORT_BVH, icon="IMPORT", text="Import BVH")
        if props.status:
            layout.label(text=props.status, icon="INFO")
        layout.label(text="Measurements are the rest pose's", icon="INFO")


classes = (ELLIMANN_PT_pose,)
