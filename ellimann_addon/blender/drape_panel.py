"""The Drape sub-panel of the ElliMann sidebar tab and its settings (``Scene.ellimann_drape``).

Registered after the main panel ``ELLIMANN_PT_main`` (its parent), hence a module of its own.
"""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from ..core.options import DRAPE, DrapeSettings
from . import ids
from .panel_base import ElliMannPanel

# Items, defaults and descriptions: core.options.DRAPE (the command line's too).
GARMENT_ITEMS = tuple((c.value, c.label, c.description) for c in DRAPE["garment"].choices)  # keys as they are
DEFAULTS = DrapeSettings()


def _subdivisions(name):
    option = DRAPE[name]
    return IntProperty(name=option.label, default=getattr(DEFAULTS, name), min=option.limits[0],
                       max=option.limits[1], description=option.description)


class ELLIMANN_PG_drape(bpy.types.PropertyGroup):
    """Drape settings of a scene."""

    garment: EnumProperty(name=DRAPE["garment"].label, items=GARMENT_ITEMS, default=DRAPE["garment"].default,
                          description=DRAPE["garment"].description)
    frames: IntProperty(name=DRAPE["frames"].label, default=DEFAULTS.frames, min=DRAPE["frames"].limits[0],
                        max=DRAPE["frames"].limits[1], soft_max=250, description=DRAPE["frames"].description)
    edge: FloatProperty(name=DRAPE["edge"].label, default=DEFAULTS.edge, min=DRAPE["edge"].limits[0],
                        max=DRAPE["edge"].limits[1], soft_min=0.01, soft_max=0.05, subtype="DISTANCE", unit="LENGTH",
                        description=DRAPE["edge"].description)
    cushions: BoolProperty(name=DRAPE["cushions"].label, default=DEFAULTS.cushions,
                           description=DRAPE["cushions"].description)
    sphere_subdivisions: _subdivisions("sphere_subdivisions")
    cushion_subdivisions: _subdivisions("cushion_subdivisions")
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
