"""The ElliMann sidebar tab's main panel: the active mannequin and its measurements. Every feature's
sub-panel hangs under it (``bl_parent_id = ids.PANEL_MAIN``, order from ``ids``)."""

import bpy

from ...core.measurements import MEASUREMENTS
from .. import ids
from ..bridge.built import built_objects
from ..bridge.convert import ellipsoid_objects
from ..bridge.selection import active_mannequin
from .base import ElliMannPanel


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


classes = (ELLIMANN_PT_main,)
