"""Synthesize from the sidebar: the request (five fields in cm), options, presets and the operator.

``Scene.ellimann_synthesis`` holds the request and options. The operator builds a new collection
named after the measurements; with "Live" on, every change of a field moves the last synthesized
mannequin in place (``live_update``). Presets (the five RMs, the ten mannequins of the paper's
Table 2.5, and the user's own) use Blender's preset system; the shipped ones are read from this
add-on's ``presets/`` folder, the user's are saved in Blender's user preset folder.
"""

import os
import pathlib
import time

import bpy
from bl_operators.presets import AddPresetBase
from bpy.props import BoolProperty, EnumProperty, FloatProperty, PointerProperty, StringProperty

from ..core.constants import ABSURD_LIMITS, MEASUREMENT_LABELS, MEASUREMENTS, RANGES, REFERENCE_MEASUREMENTS
from ..core.errors import ElliMannError
from ..core.synthesis import (
    DEFAULT_NORMALIZE,
    DEFAULT_POWER,
    POWER_LIMITS,
    cached_reference_set,
    relative_error,
    synthesize,
)
from . import ids
from .convert import ellipsoid_objects, update_collection_geometry, write_measured
from .output import add_mannequin, objects_recursive, refresh_cushions

PRESET_SUBDIR = "ellimann/synthesis"
SHIPPED_PRESETS = pathlib.Path(__file__).resolve().parent / "presets" / "synthesis"
FIELDS = {key: key.lower() for key in MEASUREMENTS}  # He -> props.he


def _on_request_change(self, context):
    if self.live and self.target is not None:
        live_update(context.scene)


def _measurement(key):
    low, high = ABSURD_LIMITS[key]
    soft_low, soft_high = RANGES[key]
    return FloatProperty(
        name=key, default=REFERENCE_MEASUREMENTS["average"][key], min=low, max=high, soft_min=soft_low,
        soft_max=soft_high, step=25, precision=2, update=_on_request_change,
        description=f"{MEASUREMENT_LABELS[key]} in cm. Reference range {soft_low:g}-{soft_high:g} cm (outside it "
                    f"the result is extrapolated); accepted {low:g}-{high:g} cm")


class ELLIMANN_PG_synthesis(bpy.types.PropertyGroup):
    """The synthesis request and options of a scene."""

    he: _measurement("He")
    sh: _measurement("Sh")
    br: _measurement("Br")
    wa: _measurement("Wa")
    hi: _measurement("Hi")
    mode: EnumProperty(
        name="Mode", default="EXACT", update=_on_request_change,
        description="How the mannequin is made from the Reference Mannequins: IDW alone misses the request by up "
                    "to a few %; Exact refines it until m_T matches",
        items=(("EXACT", "Exact", "IDW, then a gentle refinement until m_T matches the request to 0.001% "
                                  "(beyond the paper)"),
               ("IDW", "IDW", "Segmented inverse-distance weighting alone, as in the paper (m_T off by up to a few "
                              "%)")))
    output: EnumProperty(
        name="Pieces", default="ELLIPSOIDS",
        description="What Synthesize builds: ellipsoids only, or cushions (convex hulls of each cushion pair) in "
                    "place of their two ellipsoids, which are kept but hidden",
        items=(("ELLIPSOIDS", "Ellipsoids", "One ellipsoid object per part"),
               ("CUSHIONS", "Cushions", "Cushions (convex hulls) for the cushion pairs, ellipsoids for the rest; "
                                        "slower to build")))
    normalize: EnumProperty(
        name="Interpolate", default=DEFAULT_NORMALIZE.upper(), update=_on_request_change,
        description="What IDW averages over the Reference Mannequins: their proportions (ElliMann's default, "
                    "closer to the request) or their geometry as it is (the paper's Eq. 2.1)",
        items=(("PROPORTIONAL", "Proportions", "Average each part in proportion to its RM's measurements: heights "
                "to He, widths to the part's own measurement, then scale to the request"),
               ("HEIGHT", "Height Proportions", "Average heights in proportion to each RM's He, widths as they are"),
               ("NONE", "Geometry (Paper)", "Average the RMs' geometry as it is, as in the paper (Eq. 2.1)")))
    metric: EnumProperty(
        name="Distance", default="RAW", update=_on_request_change,
        description="How IDW measures the distance from the request to each Reference Mannequin's measurements "
                    "(nearer ones weigh more)",
        items=(("RAW", "cm", "IDW distances in cm, as in the paper: the wide-ranging girths weigh more than He "
                             "and Sh"),
               ("NORMALIZED", "Normalized", "Each measurement divided by its reference range L, so all five "
                                            "weigh alike")))
    power: FloatProperty(name="p", default=DEFAULT_POWER, min=POWER_LIMITS[0], max=POWER_LIMITS[1],
                         update=_on_request_change, description="IDW power (the paper uses 2)")
    live: BoolProperty(name="Live", default=False, update=_on_request_change,
                       description="Update the last synthesized mannequin in place while the fields change")
    target: PointerProperty(name="Last Synthesized", type=bpy.types.Collection,
                            poll=lambda _self, collection: collection.ellimann.is_mannequin,
                            description="The mannequin that Live updates")
    references: StringProperty(name="References", subtype="DIR_PATH", default="",
                               description="Folder with the five Reference Mannequin .json files "
                                           "(empty: the shipped reference_blends/)")
    status: StringProperty(name="Status", description="Outcome of the last live update")
    live_ms: FloatProperty(name="Live Update Time", description="Duration of the last live update (ms)")


def request_of(props):
    return {key: float(getattr(props, attr)) for key, attr in FIELDS.items()}


def _synthesize(props):
    folder = bpy.path.abspath(props.references) if props.references else None
    reference = cached_reference_set(folder)
    return synthesize(reference, request_of(props), props.mode.lower(), props.metric.lower(), props.power,
                      normalize=props.normalize.lower())


def _has_cushions(collection):
    return any(o.ellimann.kind == "CUSHION" for o in objects_recursive(collection))


def live_update(scene):
    """Move the last synthesized mannequin to the current request. Returns seconds taken, or None."""
    props = scene.ellimann_synthesis
    target = props.target
    if target is None or not target.ellimann.is_mannequin:
        return None
    start = time.perf_counter()
    try:
        mannequin, measured, warnings = _synthesize(props)
        update_collection_geometry(target, mannequin)
        write_measured(target, measured)
        if _has_cushions(target):
            refresh_cushions(target)
        if target.name != mannequin.name:
            target.name = mannequin.name
    except ElliMannError as error:
        props.status = f"Live update failed: {error}"
        return None
    seconds = time.perf_counter() - start
    props.live_ms = seconds * 1e3
    props.status = "; ".join(warnings)
    return seconds


class ELLIMANN_OT_synthesize_mannequin(bpy.types.Operator):
    """Build a new mannequin from the five measurements (segmented IDW over the Reference Mannequins)"""

    bl_idname = ids.SYNTHESIZE_MANNEQUIN
    bl_label = "Synthesize"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.scene is not None and hasattr(context.scene, "ellimann_synthesis")

    def execute(self, context):
        props = context.scene.ellimann_synthesis
        try:
            mannequin, measured, warnings = _synthesize(props)
            collection = add_mannequin(mannequin, measured, cushions=props.output == "CUSHIONS")
        except ElliMannError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        props.target = collection
        props.status = "; ".join(warnings)
        for warning in warnings:
            self.report({"WARNING"}, warning)
        worst = relative_error(measured, request_of(props)).max()
        values = ", ".join(f"{k} {measured[k]:.2f}" for k in MEASUREMENTS)
        self.report({"INFO"}, f"Synthesized '{collection.name}' ({len(ellipsoid_objects(collection))} ellipsoids, "
                              f"{props.mode.lower()}): m_T {values} cm, max error {worst:.2f}%")
        return {"FINISHED"}


class ELLIMANN_MT_measurement_presets(bpy.types.Menu):
    """Measurements of the Reference Mannequins, the paper's Table 2.5 and your own presets"""

    bl_idname = "ELLIMANN_MT_measurement_presets"
    bl_label = "Measurement Presets"  # Blender shows the last preset chosen here
    preset_subdir = PRESET_SUBDIR
    preset_operator = "script.execute_preset"

    def draw(self, _context):
        folders = [str(SHIPPED_PRESETS)] + bpy.utils.preset_paths(PRESET_SUBDIR)
        self.path_menu(folders, self.preset_operator, filter_ext=lambda ext: ext.lower() == ".py",
                       display_name=lambda path: bpy.path.display_name(os.path.basename(path), title_case=False))


class ELLIMANN_OT_add_measurement_preset(AddPresetBase, bpy.types.Operator):
    """Save the five measurements as a preset (or remove the selected one of your own)"""

    bl_idname = ids.ADD_MEASUREMENT_PRESET
    bl_label = "Add Measurement Preset"
    preset_menu = ELLIMANN_MT_measurement_presets.bl_idname
    preset_subdir = PRESET_SUBDIR
    preset_defines = ["props = bpy.context.scene.ellimann_synthesis"]
    preset_values = [f"props.{attr}" for attr in FIELDS.values()]

    @classmethod
    def poll(cls, context):
        return hasattr(context.scene, "ellimann_synthesis")


classes = (ELLIMANN_PG_synthesis, ELLIMANN_OT_synthesize_mannequin, ELLIMANN_MT_measurement_presets,
           ELLIMANN_OT_add_measurement_preset)
_register_classes, _unregister_classes = bpy.utils.register_classes_factory(classes)


def register():
    _register_classes()
    bpy.types.Scene.ellimann_synthesis = PointerProperty(type=ELLIMANN_PG_synthesis)


def unregister():
    del bpy.types.Scene.ellimann_synthesis
    _unregister_classes()
