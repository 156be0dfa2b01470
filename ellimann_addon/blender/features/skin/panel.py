"""The Skin sub-panel: Build Skin, and the active mannequin's skin (its resolution, whether it is out of date)."""

import bpy

from ....core.errors import MannequinError
from ... import ids
from ...bridge.convert import collection_to_mannequin
from ...bridge.selection import active_mannequin
from ...bridge.skin import is_stale_skin, skin_object, skin_settings_of
from ..base import SubPanel


class ELLIMANN_PT_skin(SubPanel, bpy.types.Panel):
    """The mannequin's skin: from its set's bodies, or a smooth surface over its pieces"""

    bl_idname = ids.PANEL_SKIN
    bl_label = "Skin"
    bl_order = ids.PANEL_ORDER[ids.PANEL_SKIN]

    def draw(self, context):
        layout = self.layout
        layout.operator(ids.BUILD_SKIN, icon="MOD_SKIN")
        collection = active_mannequin(context)
        obj = skin_object(collection) if collection is not None else None
        if obj is None:
            return
        settings = skin_settings_of(obj)
        made = f", {settings.describe()}" if settings is not None else ""
        layout.label(text=f"{len(obj.data.vertices):,} vertices{made}")
        try:
            stale = is_stale_skin(obj, collection_to_mannequin(collection, check=False))
        except MannequinError:  # not a whole mannequin now: Validate says why
            stale = False
        if stale:
            layout.label(text="Out of date: build again", icon="ERROR")


classes = (ELLIMANN_PT_skin,)
