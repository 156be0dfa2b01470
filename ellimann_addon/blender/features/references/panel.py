"""The Reference Set sub-panel of the ElliMann sidebar tab: the Base Mannequin, the bodies and their targets,
the folder, Build Reference Set and its progress."""

import bpy

from ....core.measurements import MEASUREMENTS
from ... import ids
from ..base import SubPanel


class ELLIMANN_PT_references(SubPanel, bpy.types.Panel):
    """Build Reference Mannequins from a traced Base Mannequin and bodies of its mesh's topology"""

    bl_idname = ids.PANEL_REFERENCES
    bl_label = "Reference Set"
    bl_order = ids.PANEL_ORDER[ids.PANEL_REFERENCES]
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context):
        return hasattr(context.scene, "ellimann_references")

    def draw(self, context):
        layout = self.layout
        props = context.scene.ellimann_references
        layout.prop(props, "base")
        header = layout.row()
        header.label(text=f"Bodies: {len(props.bodies)} (at least 3)")
        header.operator(ids.ADD_REFERENCE_BODIES, text="", icon="ADD")
        labels = layout.row(align=True)
        for key in MEASUREMENTS:
            labels.label(text=f"{key} (cm)")
        for index, row in enumerate(props.bodies):
            box = layout.column(align=True)
            line = box.row(align=True)
            line.prop(row, "body", text="")
            line.operator(ids.REMOVE_REFERENCE_BODY, text="", icon="X").index = index
            box.row(align=True).prop(row, "target", text="")
        layout.prop(props, "folder")
        column = layout.column(align=True)
        column.prop(props, "set_name")
        column.prop(props, "sex")
        layout.operator(ids.BUILD_REFERENCE_SET, icon="OUTLINER_COLLECTION")
        if props.status:
            box = layout.box()
            if 0.0 < props.progress < 1.0:
                box.prop(props, "progress", text="", slider=True)
            box.label(text=props.status)


classes = (ELLIMANN_PT_references,)
