"""The Drape sub-panel of the ElliMann sidebar tab and its settings (``Scene.ellimann_drape``).

Registered after the main panel ``ELLIMANN_PT_main`` (its parent), hence a module of its own.
"""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from ..core.collision import SUBDIVISION_RANGE
from ..core.garments import EDGE_RANGE
from . import ids
from .drape import FRAME_RANGE, DrapeSettings
from .panel_base import ElliMannPanel

GARMENT_ITEMS = (
    ("tube_dress", "Tube Dress", "Strapless tube dress, width max(Br, Hi) plus ease, its top edge pinned"),
    ("t_shirt", "T-Shirt", "Short-sleeved T-shirt from front, back and sleeve panels, sewn at the shoulders and "
                           "armholes (needs arms hanging clear of the torso)"),
)
DEFAULTS = DrapeSettings()


def _subdivisions(name, default, what):
    low, high = SUBDIVISION_RANGE
    return IntProperty(name=name, default=default, min=low, max=high,
                       description=f"Icosphere level of the {what} colliders ({low}: coarsest, {high}: finest; "
                                   "triangles = 20 * 4^level)")


class ELLIMANN_PG_drape(bpy.types.PropertyGroup):
    """Drape settings of a scene."""

    garment: EnumProperty(name="Garment", items=GARMENT_ITEMS, default="tube_dress",
                          description="Garment to cut from the mannequin's measurements and drape on it")
    frames: IntProperty(name="Frames", default=DEFAULTS.frames, min=FRAME_RANGE[0], max=FRAME_RANGE[1],
                        soft_max=250, description="Frames to simulate (from frame 1, at the scene's frame rate)")
    edge: FloatProperty(name="Cloth Edge", default=DEFAULTS.edge, min=EDGE_RANGE[0], max=EDGE_RANGE[1],
                        soft_min=0.01, soft_max=0.05, subtype="DISTANCE", unit="LENGTH",
                        description="Edge length of the garment's mesh (smaller: finer folds, slower)")
    cushions: BoolProperty(name="Cushions", default=DEFAULTS.cushions,
                           description="Collide with the cushions and the ellipsoids not in one (off: every "
                                       "ellipsoid)")
    sphere_subdivisions: _subdivisions("Ellipsoid Resolution", DEFAULTS.sphere_subdivisions, "ellipsoid")
    cushion_subdivisions: _subdivisions("Cushion Resolution", DEFAULTS.cushion_subdivisions, "cushion")
    status: StringProperty(name="Last Drape", description="Outcome of the last drape")

    def settings(self):
        return DrapeSettings(frames=self.frames, edge=self.edge, cushions=self.cushions,
                             sphere_subdivisions=self.sphere_subdivisions,
                             cushion_subdivisions=self.cushion_subdivisions)


class ELLIMANN_PT_drape(ElliMannPanel, bpy.types.Panel):
    """Drape a garment on the active mannequin with Blender cloth"""

    bl_idname = ids.PANEL_DRAPE
    bl_label = "Drape"
    bl_parent_id = ids.PANEL_MAIN
    bl_order = ids.DRAPE_ORDER

    @classmethod
    def poll(cls, context):
        return hasattr(context.scene, "ellimann_drape")

    def draw(self, context):
        layout = self.layout
        props = context.scene.ellimann_drape
        layout.row().prop(props, "garment", expand=True)
        column = layout.column(align=True)
        column.prop(props, "frames")
        column.prop(props, "edge")
        column = layout.column(align=True)
        column.prop(props, "cushions")
        column.prop(props, "sphere_subdivisions")
        row = column.row()
        row.enabled = props.cushions
        row.prop(props, "cushion_subdivisions")
        layout.operator(ids.DRAPE_GARMENT, icon="MOD_CLOTH")
        if props.status:
            box = layout.box()
            for line in props.status.split("; "):
                box.label(text=line)


classes = (ELLIMANN_PG_drape, ELLIMANN_PT_drape)
_register_classes, _unregister_classes = bpy.utils.register_classes_factory(classes)


def register():
    _register_classes()
    bpy.types.Scene.ellimann_drape = PointerProperty(type=ELLIMANN_PG_drape)


def unregister():
    del bpy.types.Scene.ellimann_drape
    _unregister_classes()
