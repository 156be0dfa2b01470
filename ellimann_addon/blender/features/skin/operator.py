"""Build Skin: the active mannequin's skin (``core.skin``), written into its built Skin collection (rebuilt in place),
weighted to the bones and bound to its armature if it has one (``services.skin``)."""

import time

import bpy
from bpy.props import EnumProperty, FloatProperty

from ....core.errors import ElliMannError
from ....core.job.make import make
from ....core.job.request import Request, check
from ....core.mannequin.skin_record import SkinSettings
from ....core.settings import SKIN, VOXEL_RANGE_MM
from ... import ids
from ...bridge.convert import rig_object
from ...services.skin import add_skin
from ..base import MannequinOperator, OperatorError, mannequin_or_cancel
from . import live


def kind_property(update=None):
    option = SKIN["skin_kind"]
    return EnumProperty(
        name=option.label,
        items=option.enum_items(),
        default=option.enum_default,
        description=option.description,
        **({"update": update} if update else {}),
    )


def level_property(update=None):
    option = SKIN["skin_level"]
    return EnumProperty(
        name=option.label,
        items=option.enum_items(),
        default=option.enum_default,
        description=option.description,
        **({"update": update} if update else {}),
    )


def voxel_property():
    option = SKIN["skin_voxel"]
    return FloatProperty(
        name=option.label,
        default=0.0,
        min=0.0,
        max=VOXEL_RANGE_MM[1],
        description=f"{option.description}, {VOXEL_RANGE_MM[0]:g} to {VOXEL_RANGE_MM[1]:g}; 0: the level's",
    )


def blend_property():
    option = SKIN["skin_blend"]
    return FloatProperty(
        name=option.label,
        default=option.default,
        min=option.limits[0],
        max=option.limits[1],
        description=option.description,
    )


def settings_of(level, voxel_mm=0.0, blend=SKIN["skin_blend"].default, kind="PIECES"):
    """SkinSettings of a panel's kind and level (enum items), voxel (0: the level's) and blend; ElliMannError names a
    bad one. Blender's float properties are single precision: their values are rounded to what was typed."""
    return SkinSettings.at_level(level.lower(), round(voxel_mm, 4) or None, round(blend, 6), kind.lower())


class ELLIMANN_OT_build_skin(MannequinOperator, bpy.types.Operator):
    """Build the active mannequin's skin (its set's bodies, or a smooth surface over its pieces), bound to its armature"""  # noqa: E501

    bl_idname = ids.BUILD_SKIN
    bl_label = "Build Skin"
    bl_options = {"REGISTER", "UNDO"}

    kind: kind_property()
    level: level_property()
    voxel: voxel_property()
    blend: blend_property()

    def run(self, context, collection):
        mannequin = mannequin_or_cancel(collection)
        window_manager = context.window_manager
        started = time.perf_counter()
        window_manager.progress_begin(0.0, 1.0)
        try:
            settings = settings_of(self.level, self.voxel, self.blend, self.kind)
            job = check(Request(mannequin=mannequin, skin=settings))
            result = make(job, lambda fraction, _message: window_manager.progress_update(fraction), bones=True)
            skin = result.skin.skin
            obj = add_skin(collection, skin)  # the core's work is done: from here the scene changes
        except (ElliMannError, RuntimeError) as error:
            raise OperatorError(" ".join(str(error).split())) from None
        finally:
            window_manager.progress_end()
        live.remember(obj, skin)
        if mannequin.joints is None:
            bound = "no joints: it will not pose"
        elif rig_object(collection) is None:
            bound = "weighted to the bones; Add Armature to pose it"
        else:
            bound = "bound to the armature"
        self.report(
            {"INFO"},
            f"Built the {skin.settings.describe()} of '{collection.name}': {len(skin.vertices):,} vertices, "
            f"{bound} ({time.perf_counter() - started:.1f} s)",
        )
        return {"FINISHED"}


classes = (ELLIMANN_OT_build_skin,)
