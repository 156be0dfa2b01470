"""The Drape feature's scene settings, ``Scene.ellimann_drape`` (what ``DrapeSettings`` the operator drapes with)."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from ....core.drape.settings import DrapeSettings
from ....core.settings import DRAPE
from ..pose.operators import POSE_ITEMS

REST = "REST"
# The body under the cloth: as traced, or moving from rest into a standard pose or the walk.
BODY_POSE_ITEMS = (
    (REST, "Rest", "The mannequin at rest (the traced A-pose), standing still"),
    *(item for item in POSE_ITEMS if item[0] != "a_pose"),
)

# Items, defaults and descriptions: core.drape.settings.DRAPE (the command line's too).
DEFAULTS = DrapeSettings()


def _choice(name):
    """An EnumProperty of DRAPE's option ``name``: its choices' values (the keys as they are) are the items."""
    option = DRAPE[name]
    return EnumProperty(
        name=option.label,
        items=tuple((c.value, c.label, c.description) for c in option.choices),
        default=option.default,
        description=option.description,
    )


def _subdivisions(name):
    option = DRAPE[name]
    return IntProperty(
        name=option.label,
        default=getattr(DEFAULTS, name),
        min=option.limits[0],
        max=option.limits[1],
        description=option.description,
    )


class ELLIMANN_PG_drape(bpy.types.PropertyGroup):
    """Drape settings of a scene."""

    garment: _choice("garment")
    frames: IntProperty(
        name=DRAPE["frames"].label,
        default=DEFAULTS.frames,
        min=DRAPE["frames"].limits[0],
        max=DRAPE["frames"].limits[1],
        soft_max=250,
        description=DRAPE["frames"].description,
    )
    edge: FloatProperty(
        name=DRAPE["edge"].label,
        default=DEFAULTS.edge,
        min=DRAPE["edge"].limits[0],
        max=DRAPE["edge"].limits[1],
        soft_min=0.01,
        soft_max=0.05,
        subtype="DISTANCE",
        unit="LENGTH",
        description=DRAPE["edge"].description,
    )
    collider: _choice("collider")
    skin_level: _choice("skin_level")
    cushions: BoolProperty(
        name=DRAPE["cushions"].label, default=DEFAULTS.cushions, description=DRAPE["cushions"].description
    )
    sphere_subdivisions: _subdivisions("sphere_subdivisions")
    cushion_subdivisions: _subdivisions("cushion_subdivisions")
    pose: EnumProperty(
        name="Body",
        items=BODY_POSE_ITEMS,
        default=REST,
        description="The body under the cloth: at rest, or turning from rest into a standard pose "
        "(then holding it) or walking, the cloth following (needs joints)",
    )
    status: StringProperty(name="Last Drape", description="Outcome of the last drape")

    def settings(self):
        return DrapeSettings(
            collider=self.collider,
            skin_level=self.skin_level,
            frames=self.frames,
            edge=self.edge,
            cushions=self.cushions,
            sphere_subdivisions=self.sphere_subdivisions,
            cushion_subdivisions=self.cushion_subdivisions,
        )


classes = (ELLIMANN_PG_drape,)


def register_hooks():
    bpy.types.Scene.ellimann_drape = PointerProperty(type=ELLIMANN_PG_drape)


def unregister_hooks():
    del bpy.types.Scene.ellimann_drape
