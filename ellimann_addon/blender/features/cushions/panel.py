"""The Cushions sub-panel: build them, and how many are out of date."""

import bpy

from ... import ids
from ...bridge.built import built_objects, is_stale
from ...bridge.selection import active_mannequin, part_lookup
from ..base import SubPanel


class ELLIMANN_PT_cushions(SubPanel, bpy.types.Panel):
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


classes = (ELLIMANN_PT_cushions,)
