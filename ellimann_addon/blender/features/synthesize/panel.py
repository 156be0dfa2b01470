"""The Synthesize sub-panel of the ElliMann sidebar tab: presets and a measurement file, the request and its m_T,
options, Live."""

import bpy

from ....core.measurements import EXTRA_MEASUREMENTS, MEASUREMENT_LABELS, MEASUREMENTS
from ... import ids
from ..base import SubPanel
from .presets import ELLIMANN_MT_measurement_presets
from .request import FIELDS


class ELLIMANN_PT_synthesize(SubPanel, bpy.types.Panel):
    """Type five measurements, get a mannequin"""

    bl_idname = ids.PANEL_SYNTHESIZE
    bl_label = "Synthesize"
    bl_order = ids.SYNTHESIZE_ORDER

    @classmethod
    def poll(cls, context):
        return hasattr(context.scene, "ellimann_synthesis")

    def draw(self, context):
        layout = self.layout
        props = context.scene.ellimann_synthesis
        target = props.target
        measured = tuple(target.ellimann.measured) if target is not None and target.ellimann.has_measured else None

        row = layout.row(align=True)
        row.menu(ids.MENU_MEASUREMENT_PRESETS, text=ELLIMANN_MT_measurement_presets.bl_label)
        row.operator(ids.ADD_MEASUREMENT_PRESET, text="", icon="ADD")
        row.operator(ids.ADD_MEASUREMENT_PRESET, text="", icon="REMOVE").remove_active = True
        layout.operator(ids.OPEN_MEASUREMENT_FILE, icon="FILEBROWSER")

        header = layout.row()
        header.label(text="Request (cm)")
        header.label(text="m_T (cm)" if measured else "")
        column = layout.column(align=True)
        for index, key in enumerate(MEASUREMENTS):
            row = column.row()
            row.prop(props, FIELDS[key], text=MEASUREMENT_LABELS[key])
            row.label(text=f"{measured[index]:.2f}" if measured else "")

        extra = layout.column(align=True)
        extra.label(text="More (optional, cm)")
        for key in EXTRA_MEASUREMENTS:
            row = extra.row(align=True)
            row.prop(props, f"use_{key}", text="")
            field = row.row(align=True)
            field.active = getattr(props, f"use_{key}")
            field.prop(props, key)

        layout.row().prop(props, "mode", expand=True)
        layout.row().prop(props, "output", expand=True)
        row = layout.row()
        row.prop(props, "skin")
        kind = row.row()
        kind.active = props.skin
        kind.prop(props, "skin_kind", text="")
        level = row.row()
        level.active = props.skin and props.skin_kind != "BODY"
        level.prop(props, "skin_level", text="")
        options = layout.column(align=True)
        options.prop(props, "normalize")
        options.prop(props, "metric")
        options.prop(props, "power")
        layout.row().prop(props, "reference_set", expand=True)
        if props.reference_set == "FOLDER":
            layout.prop(props, "references")

        layout.operator(ids.SYNTHESIZE_MANNEQUIN, icon="OUTLINER_OB_ARMATURE")
        layout.operator(ids.SYNTHESIZE_FROM_MESH, icon="MESH_DATA")
        row = layout.row()
        row.prop(props, "live")
        if target is not None:
            row.label(text=f"{target.name}" + (f" ({props.live_ms:.1f} ms)" if props.live_ms else ""))
        if props.status:
            box = layout.box()
            for line in props.status.split("; "):
                box.label(text=line, icon="ERROR")


classes = (ELLIMANN_PT_synthesize,)
