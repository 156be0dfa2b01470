"""The Measure sub-panel: measure (and draw the sections), the last m_T."""

import bpy

from ....core.constants import MEASUREMENT_LABELS, MEASUREMENTS
from ... import ids
from ...bridge.selection import active_mannequin
from ..base import SubPanel


class ELLIMANN_PT_measure(SubPanel, bpy.types.Panel):
    """m_T: height, shoulder width, breast, waist and hip perimeters"""

    bl_idname = ids.PANEL_MEASURE
    bl_label = "Measure"
    bl_order = ids.PANEL_ORDER[ids.PANEL_MEASURE]

    def draw(self, context):
        layout = self.layout
        col = layout.column(align=True)
        col.operator(ids.MEASURE_MANNEQUIN, icon="DRIVER_DISTANCE")
        col.operator(ids.MEASURE_MANNEQUIN, text="Measure and Draw Sections").draw_sections = True
        collection = active_mannequin(context)
        if collection is not None and collection.ellimann.has_measured:
            col = layout.column(align=True)
            for index, key in enumerate(MEASUREMENTS):
                col.label(text=f"{MEASUREMENT_LABELS[key]}: {collection.ellimann.measured[index]:.2f} cm")


classes = (ELLIMANN_PT_measure,)
