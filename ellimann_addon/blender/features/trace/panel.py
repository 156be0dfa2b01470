"""The Trace sub-panel: new mannequin, add and fit ellipsoids, mirror them."""

import bpy

from ... import ids
from ..base import SubPanel


class ELLIMANN_PT_trace(SubPanel, bpy.types.Panel):
    """Trace a Base Mannequin over a reference mesh"""

    bl_idname = ids.PANEL_TRACE
    bl_label = "Trace"
    bl_order = ids.PANEL_ORDER[ids.PANEL_TRACE]

    def draw(self, context):
        layout = self.layout
        col = layout.column(align=True)
        col.operator(ids.NEW_MANNEQUIN, icon="OUTLINER_COLLECTION")
        col.operator(ids.ADD_ELLIPSOID, icon="MESH_UVSPHERE")
        layout.label(text="Fit to selected vertices (Edit Mode):")
        row = layout.row(align=True)
        for mode, text in (("inscribed", "Inscribed"), ("moments", "Moments"), ("enclosing", "Enclosing")):
            row.operator(ids.FIT_ELLIPSOID, text=text).mode = mode
        layout.label(text="Mirror across x = 0:")
        col = layout.column(align=True)
        col.operator(ids.MIRROR_ELLIPSOIDS, icon="MOD_MIRROR")
        row = col.row(align=True)
        row.operator(ids.MIRROR_SIDE, text="Left to Right").source = "L"
        row.operator(ids.MIRROR_SIDE, text="Right to Left").source = "R"


classes = (ELLIMANN_PT_trace,)
