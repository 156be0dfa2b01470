"""The Measure sub-panel: measure (and draw the sections), the last m_T."""

import json

import bpy

from ....core.measurements import MEASUREMENT_LABELS, MEASUREMENTS
from ... import ids
from ...bridge.selection import active_mannequin
from ..base import SubPanel
from .body import RESULT_PROPERTY

LABELS = {**MEASUREMENT_LABELS, **MEASUREMENT_LABELS}


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
        layout.operator(ids.MEASURE_BODY, icon="MESH_DATA")
        obj = context.active_object
        if obj is not None and RESULT_PROPERTY in obj:
            col = layout.column(align=True)
            col.label(text=f"'{obj.name}' (body mesh):")
            for key, value in json.loads(obj[RESULT_PROPERTY]).items():
                col.label(text=f"{LABELS.get(key, key)}: {value:.2f} cm")
        collection = active_mannequin(context)
        if collection is not None and collection.ellimann.has_measured:
            col = layout.column(align=True)
            for index, key in enumerate(MEASUREMENTS):
                col.label(text=f"{MEASUREMENT_LABELS[key]}: {collection.ellimann.measured[index]:.2f} cm")


classes = (ELLIMANN_PT_measure,)
