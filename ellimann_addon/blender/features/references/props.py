"""The Build Reference Set feature's scene settings, ``Scene.ellimann_references``: the Base Mannequin, the
bodies with their targets, where the set goes."""

import bpy
from bpy.props import (
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    PointerProperty,
    StringProperty,
)

from ....core.constants import REFERENCE_MEASUREMENTS
from ....core.measurements import ABSURD_LIMITS, MEASUREMENTS

SEX_ITEMS = (
    ("NONE", "Unspecified", "The set has no sex recorded"),
    ("female", "Female", "A set of female bodies"),
    ("male", "Male", "A set of male bodies"),
)
_LOW = min(low for low, _ in ABSURD_LIMITS.values())
_HIGH = max(high for _, high in ABSURD_LIMITS.values())


def _is_mesh(_self, obj):
    return obj.type == "MESH" and not obj.ellimann.is_part


class ELLIMANN_PG_reference_body(bpy.types.PropertyGroup):
    """One body of the set and the measurements its Reference Mannequin must meet."""

    body: PointerProperty(
        name="Body",
        type=bpy.types.Object,
        poll=_is_mesh,
        description="A body mesh with the same vertices (count and order) as the mesh the Base "
        "Mannequin was traced on; its name names the Reference Mannequin",
    )
    target: FloatVectorProperty(
        name="Targets (cm)",
        size=len(MEASUREMENTS),
        min=_LOW,
        max=_HIGH,
        default=tuple(REFERENCE_MEASUREMENTS["average"][k] for k in MEASUREMENTS),
        description="He, Sh, Br, Wa, Hi (cm) the Reference Mannequin is refined to meet "
        "(typed: ElliMann does not measure meshes yet)",
    )


class ELLIMANN_PG_references(bpy.types.PropertyGroup):
    """Build Reference Set settings of a scene."""

    base: PointerProperty(
        name="Base Mannequin",
        type=bpy.types.Collection,
        poll=lambda _self, collection: collection.ellimann.is_mannequin,
        description="The traced Base Mannequin: every part records the vertices Fit Ellipsoid fitted it to",
    )
    bodies: CollectionProperty(
        type=ELLIMANN_PG_reference_body,
        name="Bodies",
        description="At least 3 bodies of the traced mesh's topology, each with its targets",
    )
    folder: StringProperty(
        name="Folder",
        subtype="DIR_PATH",
        default="",
        description="Where the set is written: the Reference Mannequins' .json files, the base "
        "and reference_set.json (an empty or new folder, or a set to replace)",
    )
    set_name: StringProperty(
        name="Set Name", default="", description="The set's name in its manifest (empty: the folder's name)"
    )
    sex: EnumProperty(name="Sex", items=SEX_ITEMS, default="NONE", description="The sex the manifest records")
    progress: FloatProperty(
        name="Progress", default=0.0, min=0.0, max=1.0, subtype="FACTOR", description="How far the running build is"
    )
    status: StringProperty(name="Status", description="What the build is doing, or how the last one ended")


classes = (ELLIMANN_PG_reference_body, ELLIMANN_PG_references)


def register_hooks():
    bpy.types.Scene.ellimann_references = PointerProperty(type=ELLIMANN_PG_references)


def unregister_hooks():
    del bpy.types.Scene.ellimann_references
