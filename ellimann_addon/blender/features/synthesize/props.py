"""The Synthesize feature's scene settings, ``Scene.ellimann_synthesis``: the request (five fields in cm)
and the options; every change of a field makes a live update when Live is on (:mod:`.live`)."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, PointerProperty, StringProperty

from ....core.constants import RANGES, REFERENCE_MEASUREMENTS
from ....core.measurements import (
    ABSURD_LIMITS,
    EXTRA_ABSURD_LIMITS,
    EXTRA_DEFAULTS,
    EXTRA_MEASUREMENTS,
    MEASUREMENT_LABELS,
)
from ....core.synthesis.options import SYNTHESIS
from ..skin.operator import kind_property, level_property
from .live import on_request_change
from .request import REFERENCE_SET_ITEMS


def _measurement(key):
    low, high = ABSURD_LIMITS[key]
    soft_low, soft_high = RANGES[key]
    return FloatProperty(
        name=key,
        default=REFERENCE_MEASUREMENTS["average"][key],
        min=low,
        max=high,
        soft_min=soft_low,
        soft_max=soft_high,
        step=25,
        precision=2,
        update=on_request_change,
        description=f"{MEASUREMENT_LABELS[key]} in cm. The female set's reference range {soft_low:g}-{soft_high:g} "
        f"cm (outside its set's range the result is extrapolated); accepted {low:g}-{high:g} cm",
    )


def _option(name):
    """A synthesis option's property from ``core.synthesis.options.SYNTHESIS`` (the command line's table too)."""
    option = SYNTHESIS[name]
    if option.choices:
        return EnumProperty(
            name=option.label,
            default=option.enum_default,
            update=on_request_change,
            description=option.description,
            items=option.enum_items(),
        )
    return FloatProperty(
        name=option.label,
        default=option.default,
        min=option.limits[0],
        max=option.limits[1],
        update=on_request_change,
        description=option.description,
    )


class ELLIMANN_PG_synthesis(bpy.types.PropertyGroup):
    """The synthesis request and options of a scene."""

    he: _measurement("He")
    sh: _measurement("Sh")
    br: _measurement("Br")
    wa: _measurement("Wa")
    hi: _measurement("Hi")
    mode: _option("mode")
    output: EnumProperty(
        name="Pieces",
        default="ELLIPSOIDS",
        description="What Synthesize builds: ellipsoids only, or cushions (convex hulls of each cushion pair) in "
        "place of their two ellipsoids, which are kept but hidden",
        items=(
            ("ELLIPSOIDS", "Ellipsoids", "One ellipsoid object per part"),
            (
                "CUSHIONS",
                "Cushions",
                "Cushions (convex hulls) for the cushion pairs, ellipsoids for the rest; slower to build",
            ),
        ),
    )
    skin: BoolProperty(
        name="Skin",
        default=False,
        update=on_request_change,
        description="Give the mannequin a skin (from the set's own bodies where it has them, or a smooth surface over "
        "its pieces), bound to its armature. Live, the skin follows each step (the bodies' blend, or the pieces) and "
        "is made again once the fields are still",
    )
    skin_kind: kind_property()
    skin_level: level_property()
    normalize: _option("normalize")
    metric: _option("metric")
    power: _option("power")
    live: BoolProperty(
        name="Live",
        default=False,
        update=on_request_change,
        description="Update the last synthesized mannequin in place while the fields change",
    )
    target: PointerProperty(
        name="Last Synthesized",
        type=bpy.types.Collection,
        poll=lambda _self, collection: collection.ellimann.is_mannequin,
        description="The mannequin that Live updates",
    )
    reference_set: EnumProperty(
        name="Reference Set",
        items=REFERENCE_SET_ITEMS,
        default="FEMALE",
        update=on_request_change,
        description="The Reference Mannequins to synthesize from: the shipped female or "
        "male set (the paper's 40 pieces, or the fine topology's), or a folder of your own",
    )
    references: StringProperty(
        name="References",
        subtype="DIR_PATH",
        default="",
        update=on_request_change,
        description="With Reference Set Folder: a reference-set folder, reference_set.json "
        "and the Reference Mannequins' .json files it lists (Build Reference Set "
        "writes one), or the five files of Table 2.3",
    )
    status: StringProperty(name="Status", description="Outcome of the last live update")
    live_ms: FloatProperty(name="Live Update Time", description="Duration of the last live update (ms)")


def _extra_fields():
    """Each extra measurement: a checkbox (given or not) and its value in cm (docs/measurements.md)."""
    fields = {}
    for key in EXTRA_MEASUREMENTS:
        low, high = EXTRA_ABSURD_LIMITS[key]
        label = MEASUREMENT_LABELS[key]
        fields[f"use_{key}"] = BoolProperty(
            name=label,
            default=False,
            update=on_request_change,
            description=f"Give the {label.lower()} too (exact mode meets it with pieces of its own; unticked, the "
            "reference set gives it)",
        )
        fields[key] = FloatProperty(
            name=label,
            default=EXTRA_DEFAULTS[key],
            min=low,
            max=high,
            step=25,
            precision=2,
            update=on_request_change,
            description=f"{label} in cm (docs/measurements.md); accepted {low:g}-{high:g} cm",
        )
    return fields


ELLIMANN_PG_synthesis.__annotations__.update(_extra_fields())
classes = (ELLIMANN_PG_synthesis,)


def register_hooks():
    bpy.types.Scene.ellimann_synthesis = PointerProperty(type=ELLIMANN_PG_synthesis)


def unregister_hooks():
    del bpy.types.Scene.ellimann_synthesis
