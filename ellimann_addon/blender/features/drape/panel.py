"""The Drape sub-panel of the ElliMann sidebar tab: garment, cloth and collider (the pieces or the skin), Drape."""

import bpy

from ... import ids
from ..base import SubPanel


class ELLIMANN_PT_drape(SubPanel, bpy.types.Panel):
    """Drape a garment on the active mannequin with Blender cloth"""

    bl_idname = ids.PANEL_DRAPE
    bl_label = "Drape"
    bl_order = ids.DRAPE_ORDER

    @classmethod
    def poll(cls, context):
        return hasattr(context.scene, "ellimann_drape")

    def draw(self, context):
        layout = self.layout
        props = context.scene.ellimann_drape
        layout.row().prop(props, "garment", expand=True)
        column = layout.column(align=True)
        column.prop(props, "pose")
        column.prop(props, "frames")
        column.prop(props, "edge")
        layout.row().prop(props, "collider", expand=True)
        column = layout.column(align=True)
        if props.collider == "skin":
            column.prop(props, "skin_level")
        else:
            column.prop(props, "cushions")
            column.prop(props, "sphere_subdivisions")
            row = column.row()
            row.enabled = props.cushions
            row.prop(props, "cushion_subdivisions")
        layout.operator(ids.DRAPE_GARMENT, icon="MOD_CLOTH")
        if props.status:
            box = layout.box()
            for line in props.status.split("; "):
                box.label(text=line)


classes = (ELLIMANN_PT_drape,)
