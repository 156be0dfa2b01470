"""The ElliMann sidebar tab: the active mannequin and its measurements, then one sub-panel per task.

Sub-panels set ``bl_parent_id = ids.PANEL_MAIN`` and their order from ``ids.PANEL_ORDER``.
"""

import bpy

from ..core.constants import MEASUREMENT_LABELS, MEASUREMENTS
from . import ids
from .built import built_objects, is_stale
from .checks import EXPLANATIONS, FIXABLE, frame_issue
from .convert import ellipsoid_objects, is_ellipsoid
from .panel_base import ElliMannPanel
from .selection import active_mannequin, part_lookup, selected_ellipsoids


class ELLIMANN_PT_main(ElliMannPanel, bpy.types.Panel):
    """The active mannequin: role, measured and target values"""

    bl_idname = ids.PANEL_MAIN
    bl_label = "ElliMann"

    def draw(self, context):
        layout = self.layout
        collection = active_mannequin(context)
        if collection is None:
            layout.label(text="No active mannequin", icon="INFO")
            layout.label(text="Select a part, or make a mannequin collection active")
            layout.operator(ids.NEW_MANNEQUIN, icon="OUTLINER_COLLECTION")
            return
        props = collection.ellimann
        layout.label(text=collection.name, icon="OUTLINER_COLLECTION")
        layout.prop(props, "role")
        count = len(ellipsoid_objects(collection))
        cushions = len(built_objects(collection, "CUSHION"))
        layout.label(text=f"{count} ellipsoids, {cushions} cushions")
        layout.operator(ids.EXPORT_MANNEQUIN, icon="EXPORT")
        if not (props.has_measured or props.has_target):
            layout.label(text="Not measured yet")
            return
        grid = layout.grid_flow(columns=3, even_columns=True, align=True)
        for text in ("cm", "Measured", "Target"):
            grid.label(text=text)
        for index, key in enumerate(MEASUREMENTS):
            grid.label(text=key)
            grid.label(text=f"{props.measured[index]:.2f}" if props.has_measured else "-")
            grid.label(text=f"{props.target[index]:.2f}" if props.has_target else "-")


class _SubPanel(ElliMannPanel):
    bl_parent_id = ids.PANEL_MAIN


class ELLIMANN_PT_trace(_SubPanel, bpy.types.Panel):
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


class ELLIMANN_PT_part(_SubPanel, bpy.types.Panel):
    """The active object's ElliMann fields"""

    bl_idname = ids.PANEL_PART
    bl_label = "Part"
    bl_order = ids.PANEL_ORDER[ids.PANEL_PART]

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and obj.ellimann.is_part

    def draw(self, context):
        layout = self.layout
        obj = context.active_object
        props = obj.ellimann
        if not is_ellipsoid(obj):
            layout.label(text=f"{props.kind.title()} built by ElliMann", icon="INFO")
            layout.prop(props, "part_name")
            return
        layout.use_property_split = True
        layout.prop(props, "part_name")
        layout.prop(props, "side")
        layout.prop(props, "region")
        layout.prop(props, "girth")
        layout.prop(props, "partner")
        layout.label(text="Depends on:")
        layout.row(align=True).prop(props, "depends")
        issue = frame_issue(obj)
        if issue is not None:
            box = layout.box()
            box.alert = True
            box.label(text=str(issue), icon="ERROR")
            for line in _wrap(EXPLANATIONS[issue.kind]):
                box.label(text=line)
            if issue.kind in FIXABLE:
                box.operator(ids.FIX_FRAMES, icon="MODIFIER").scope = "SELECTED"


def _wrap(text, width=48):
    """Labels do not wrap: split a sentence into short lines."""
    lines, line = [], ""
    for word in text.split():
        if line and len(line) + len(word) >= width:
            lines.append(line)
            line = ""
        line = f"{line} {word}".strip()
    return lines + [line] if line else lines


class ELLIMANN_PT_clean(_SubPanel, bpy.types.Panel):
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


class ELLIMANN_PT_cushions(_SubPanel, bpy.types.Panel):
    """Convex hulls of cushion pairs"""

    bl_idname = ids.PANEL_CUSHIONS
    bl_label = "Cushions"
    bl_order = ids.PANEL_ORDER[ids.PANEL_CUSHIONS]

    def draw(self, context):
        layout = self.layout
        layout.operator(ids.BUILD_CUSHIONS, icon="MESH_CAPSULE")
        collection = active_mannequin(context)
        if collection is not None:
            cushions = built_objects(collection, "CUSHION")
            layout.label(text=f"{len(cushions)} cushions built")
            parts = part_lookup(collection)
            stale = sum(is_stale(c, parts) for c in cushions)
            if stale:
                layout.label(text=f"{stale} out of date: build again", icon="ERROR")


class ELLIMANN_PT_measure(_SubPanel, bpy.types.Panel):
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


classes = (ELLIMANN_PT_main, ELLIMANN_PT_trace, ELLIMANN_PT_part, ELLIMANN_PT_clean, ELLIMANN_PT_cushions,
           ELLIMANN_PT_measure)
register, unregister = bpy.utils.register_classes_factory(classes)
