"""The Drape feature's scene settings, ``Scene.ellimann_drape`` (what ``DrapeSettings`` the operator drapes with)."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from ....core.constants import COLLIDER_LEVELS
from ....core.garments import EDGE_RANGE
from ...services.drape import FRAME_RANGE, DrapeSettings

GARMENT_ITEMS = (
    ("tube_dress", "Tube Dress", "Strapless tube dress, width max(Br, Hi) plus ease, its top edge pinned"),
    ("t_shirt", "T-Shirt", "Short-sleeved T-shirt from front, back and sleeve panels, sewn at the shoulders and "
                           "armholes (needs arms hanging clear of the torso)"),
)
DEFAULTS = DrapeSettings()


def _subdivisions(name, default, what):
    low, high = COLLIDER_LEVELS
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


classes = (ELLIMANN_PG_drape,)


def register_hooks():
    bpy.types.Scene.ellimann_drape = PointerProperty(type=ELLIMANN_PG_drape)


def unregister_hooks():
    del bpy.types.Scene.ellimann_drape
