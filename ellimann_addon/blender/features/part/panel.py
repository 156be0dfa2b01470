"""The Part sub-panel: the active object's ElliMann fields, and the repair of a broken frame."""

import bpy

from ... import ids
from ...bridge.checks import EXPLANATIONS, FIXABLE, frame_issue
from ...bridge.convert import is_ellipsoid
from ..base import SubPanel


class ELLIMANN_PT_part(SubPanel, bpy.types.Panel):
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


classes = (ELLIMANN_PT_part,)
