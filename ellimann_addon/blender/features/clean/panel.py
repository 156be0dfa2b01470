"""The Clean sub-panel: validate, fix frames, relabel, symmetrize, register to world."""

import bpy

from ... import ids
from ...bridge.selection import selected_ellipsoids
from ..base import SubPanel


class ELLIMANN_PT_clean(SubPanel, bpy.types.Panel):
    """Make mannequins consistent (paper, Section 2.3.4)"""

    bl_idname = ids.PANEL_CLEAN
    bl_label = "Clean"
    bl_order = ids.PANEL_ORDER[ids.PANEL_CLEAN]

    def draw(self, context):
        layout = self.layout
        col = layout.column(align=True)
        col.operator(ids.VALIDATE_MANNEQUIN, icon="CHECKMARK")
        col.operator(ids.FIX_FRAMES, icon="MODIFIER")
        col = layout.column(align=True)
        col.operator(ids.RELABEL_AXES, icon="ORIENTATION_LOCAL")
        col.operator(ids.SYMMETRIZE_CENTRAL, icon="MOD_MIRROR")
        col.operator(ids.REGISTER_MANNEQUIN, icon="ORIENTATION_GLOBAL")
        selected = len(selected_ellipsoids(context))
        if selected:
            layout.label(text=f"{selected} ellipsoids selected")


classes = (ELLIMANN_PT_clean,)
