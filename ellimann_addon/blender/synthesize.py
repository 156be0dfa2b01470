"""Synthesize from the sidebar: the request (five fields in cm), options, presets and the operator.

``Scene.ellimann_synthesis`` holds the request and options. The operator builds a new collection
named after the measurements; with "Live" on, every change of a field moves the last synthesized
mannequin in place (``live_update``). Presets (the five RMs, the ten mannequins of the paper's
Table 2.5, and the user's own) use Blender's preset system; the shipped ones are read from this
add-on's ``presets/`` folder, the user's are saved in Blender's user preset folder. A preset sets
five fields but makes one live update (the preset menu's ``reset_cb`` / ``post_cb`` hold it back),
and the menu runs it through ``ELLIMANN_OT_apply_measurement_preset``, so that fields and mannequin
change in one undo step (Blender's ``script.execute_preset`` makes none).

Live updates with cushions keep up with a dragged slider by moving the existing cushion meshes:
their vertices are rewritten in place (``core.cushion.cushion_vertices``, every pair in one
vectorised call; same vertex order at the same resolution) and their faces kept. Those faces were
made convex for the previous ellipsoids, so the cushions count as out of date until the fields
have been still for ``LIVE_SETTLE_SECONDS``; a timer then rebuilds them exactly (``settle_live``).
Blender records a slider's undo step when it is released, before that timer, and a file may be
saved before it too: undo, redo and opening a file can bring moved cushions back, so handlers
(``settle_restored``) start the timer again whenever a live target's cushions are out of date.
"""

import os
import pathlib
import re
import sys
import time

import bpy
import numpy as np
from bl_operators.presets import AddPresetBase
from bpy.props import BoolProperty, EnumProperty, FloatProperty, PointerProperty, StringProperty

from ..core.constants import ABSURD_LIMITS, MEASUREMENT_LABELS, MEASUREMENTS, RANGES, REFERENCE_MEASUREMENTS
from ..core.cushion import DEFAULT_SUBDIVISIONS, cushion_vertices
from ..core.errors import ElliMannError
from ..core.measure import measurement_line
from ..core.mesh import icosphere_level
from ..core.options import SYNTHESIS, SynthesisOptions
from ..core.synthesis import cached_reference_set, relative_error, synthesize
from . import ids
from .built import built_objects, is_stale
from .convert import ellipsoid_objects, update_collection_geometry, write_measured
from .cushions import rigid_frame
from .output import LIVE_SUBDIVISIONS, add_mannequin, refresh_cushions
from .selection import part_lookup

PRESET_SUBDIR = "ellimann/synthesis"
SHIPPED_PRESETS = pathlib.Path(__file__).resolve().parent / "presets" / "synthesis"
FIELDS = {key: key.lower() for key in MEASUREMENTS}  # He -> props.he
LIVE_SETTLE_SECONDS = 0.5  # fields still this long: the live target's cushions are rebuilt exactly
LIVE_NAME_KEY = "ellimann_live_name"  # on a live target: the name live updates last gave it

_held = {"depth": 0, "changed": False}  # live updates held back while a preset sets its fields
_settling = {"scenes": set()}  # names of the scenes whose live targets wait for exact cushions


def _on_request_change(self, context):
    if not (self.live and self.target is not None):
        return
    if _held["depth"]:
        _held["changed"] = True
        return
    live_update(context.scene)


def hold_live_updates():
    """Until :func:`release_live_updates`, field changes make no live update (a preset sets five at once)."""
    _held["depth"] += 1


def release_live_updates(scene):
    """End a hold; one live update if a field changed meanwhile. Returns live_update's result or None."""
    _held["depth"] = max(0, _held["depth"] - 1)
    if _held["depth"] or not _held["changed"]:
        return None
    _held["changed"] = False
    props = scene.ellimann_synthesis
    return live_update(scene) if props.live and props.target is not None else None


def _measurement(key):
    low, high = ABSURD_LIMITS[key]
    soft_low, soft_high = RANGES[key]
    return FloatProperty(
        name=key, default=REFERENCE_MEASUREMENTS["average"][key], min=low, max=high, soft_min=soft_low,
        soft_max=soft_high, step=25, precision=2, update=_on_request_change,
        description=f"{MEASUREMENT_LABELS[key]} in cm. Reference range {soft_low:g}-{soft_high:g} cm (outside it "
                    f"the result is extrapolated); accepted {low:g}-{high:g} cm")


def _option(name):
    """A synthesis option's property from ``core.options.SYNTHESIS`` (the command line's table too)."""
    option = SYNTHESIS[name]
    if option.choices:
        return EnumProperty(name=option.label, default=option.enum_default, update=_on_request_change,
                            description=option.description, items=option.enum_items())
    return FloatProperty(name=option.label, default=option.default, min=option.limits[0], max=option.limits[1],
                         update=_on_request_change, description=option.description)


class ELLIMANN_PG_synthesis(bpy.types.PropertyGroup):
    """The synthesis request and options of a scene."""

    he: _measurement("He")
    sh: _measurement("Sh")
    br: _measurement("Br")
    wa: _measurement("Wa")
    hi: _measurement("Hi")
    mode: _option("mode")
    output: EnumProperty(
        name="Pieces", default="ELLIPSOIDS",
        description="What Synthesize builds: ellipsoids only, or cushions (convex hulls of each cushion pair) in "
                    "place of their two ellipsoids, which are kept but hidden",
        items=(("ELLIPSOIDS", "Ellipsoids", "One ellipsoid object per part"),
               ("CUSHIONS", "Cushions", "Cushions (convex hulls) for the cushion pairs, ellipsoids for the rest; "
                                        "slower to build")))
    normalize: _option("normalize")
    metric: _option("metric")
    power: _option("power")
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
    return synthesize(reference, request_of(props), options_of(props))


def options_of(props):
    """The SynthesisOptions of the panel's fields."""
    return SynthesisOptions(mode=props.mode.lower(), metric=props.metric.lower(), power=props.power,
                            normalize=props.normalize.lower())


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
        cushions = built_objects(target, "CUSHION")
        if cushions:
            if move_cushions(mannequin, cushions):  # out of date until the fields are still
                _settle_later(scene)
            else:  # rebuilt exactly once; afterwards they move in place
                refresh_cushions(target, min(_level(cushions), LIVE_SUBDIVISIONS), scene_view_layer(scene))
        rename_live_target(target, mannequin.name)
    except ElliMannError as error:
        props.status = f"Live update failed: {error}"
        return None
    seconds = time.perf_counter() - start
    props.live_ms = seconds * 1e3
    props.status = "; ".join(warnings)
    return seconds


def _level(cushions):
    """The resolution most of the cushions have (DEFAULT_SUBDIVISIONS if none is an icosphere's)."""
    levels = [icosphere_level(len(o.data.vertices)) for o in cushions if o.type == "MESH"]
    levels = [level for level in levels if level is not None]
    return max(set(levels), key=levels.count) if levels else DEFAULT_SUBDIVISIONS


def move_cushions(mannequin, cushions):
    """Move the built cushions onto ``mannequin``'s ellipsoids by rewriting their vertices in place.

    Needs one cushion per pair, each with a mesh of its own at an icosphere resolution (as
    build_cushions makes them); returns False, changing nothing, otherwise. The faces are kept, so
    the cushions stay out of date (``built.is_stale``) until :func:`settle_live` rebuilds them.
    """
    topology = mannequin.topology
    pairs = np.asarray(topology.cushion_pairs, dtype=int).reshape(-1, 2)
    by_pair = {(o.ellimann.part_name, o.ellimann.partner): o for o in cushions}
    objects = [by_pair.get((topology.names[i], topology.names[j])) for i, j in pairs]
    if len(cushions) != len(pairs) or any(o is None or o.type != "MESH" or o.data.users != 1 for o in objects):
        return False
    levels = [icosphere_level(len(o.data.vertices)) for o in objects]
    if None in levels:
        return False
    for level in set(levels):
        rows = [k for k, found in enumerate(levels) if found == level]
        local = cushion_vertices(mannequin.rotation, mannequin.center, mannequin.semi_axes, pairs[rows], level)
        for k, vertices in zip(rows, local.astype(np.float32)):
            obj, first = objects[k], pairs[k, 0]
            obj.data.vertices.foreach_set("co", vertices.ravel())
            obj.data.update()
            obj.matrix_world = rigid_frame(mannequin.rotation[first], mannequin.center[first])
    return True


def _settle_later(scene):
    """(Re)start the timer that rebuilds the cushions once the fields are still (restarted by every update)."""
    if bpy.app.timers.is_registered(_settle_timer):
        bpy.app.timers.unregister(_settle_timer)
    else:  # a file load removes the timer: forget what it was to do in the old file
        _settling["scenes"].clear()
    _settling["scenes"].add(scene.name)
    bpy.app.timers.register(_settle_timer, first_interval=LIVE_SETTLE_SECONDS)


def _settle_timer():
    names, _settling["scenes"] = _settling["scenes"], set()
    for name in sorted(names):
        scene = bpy.data.scenes.get(name)
        if scene is not None:
            settle_live(scene)
    return None  # once


@bpy.app.handlers.persistent
def settle_restored(*_args):
    """undo_post, redo_post and load_post handler: start the settle timer for every scene whose live
    target has out-of-date cushions (moved in place, then recorded in an undo step or saved before the
    timer rebuilt them)."""
    for scene in bpy.data.scenes:
        props = getattr(scene, "ellimann_synthesis", None)
        target = props.target if props is not None and props.live else None
        if target is not None and target.ellimann.is_mannequin and _has_stale(
                target, built_objects(target, "CUSHION")):
            _settle_later(scene)


HANDLERS = ("undo_post", "redo_post", "load_post")


def settle_live(scene):
    """Rebuild the live target's out-of-date cushions exactly (closed convex hulls).

    Live updates call this through a timer once the fields have been still for LIVE_SETTLE_SECONDS,
    and so does an undo, a redo or opening a file that brings moved cushions back (:func:`settle_restored`).
    The hulls are rebuilt at output.LIVE_SUBDIVISIONS (642 vertices; or their own resolution if
    coarser): at Synthesize's 2,562 the rebuild takes seconds on a 40-part mannequin, at 642 about
    half a second. Synthesize again for full-resolution cushions. The ellipsoids the cushions replace
    are hidden in ``scene``'s view layer (:func:`scene_view_layer`), whatever the context's is. Returns
    the number rebuilt (0 if none was out of date, or if they could not be rebuilt: then nothing
    changed, the panel's status says why and so does one line on the console).
    """
    props = scene.ellimann_synthesis
    target = props.target
    if target is None or not target.ellimann.is_mannequin:
        return 0
    cushions = built_objects(target, "CUSHION")
    if not _has_stale(target, cushions):
        return 0
    try:
        refresh_cushions(target, min(_level(cushions), LIVE_SUBDIVISIONS), scene_view_layer(scene))
    except (ElliMannError, RuntimeError) as error:
        message = " ".join(str(error).split())
        props.status = f"Cushions not rebuilt: {message}"
        print(f"ElliMann: cushions of '{target.name}' not rebuilt: {message}", file=sys.stderr)
        return 0
    return len(built_objects(target, "CUSHION"))


def _has_stale(target, cushions):
    parts = part_lookup(target)
    return any(is_stale(c, parts) for c in cushions)


def scene_view_layer(scene):
    """The view layer ``scene`` is shown in: the context's if it is one of ``scene``'s, else that of a
    window showing ``scene``, else its first. (A timer runs in whatever context the window manager has.)"""
    context = bpy.context
    if context.view_layer is not None and context.view_layer.id_data == scene:
        return context.view_layer
    for window in context.window_manager.windows if context.window_manager else ():
        if window.scene == scene:
            return window.view_layer
    return scene.view_layers[0]


def rename_live_target(target, name):
    """Give the live target the name of its request, without renaming it on every update.

    When another collection holds that name, Blender appends a suffix ("... .001"); the target keeps
    the suffixed name (remembered on it) instead of being renamed again at each update.
    Returns True if it was renamed.
    """
    if target.name == name:
        return False
    suffixed = re.fullmatch(re.escape(name) + r"\.\d{3,}", target.name) is not None
    if suffixed and target.get(LIVE_NAME_KEY) == name and bpy.data.collections.get(name) not in (None, target):
        return False
    target.name = name
    target[LIVE_NAME_KEY] = name
    return True


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
        values = measurement_line(measured)
        self.report({"INFO"}, f"Synthesized '{collection.name}' ({len(ellipsoid_objects(collection))} ellipsoids, "
                              f"{props.mode.lower()}): m_T {values} cm, max error {worst:.2f}%")
        return {"FINISHED"}


class ELLIMANN_MT_measurement_presets(bpy.types.Menu):
    """Measurements of the Reference Mannequins, the paper's Table 2.5 and your own presets"""

    bl_idname = ids.MENU_MEASUREMENT_PRESETS
    bl_label = "Measurement Presets"  # Blender shows the last preset chosen here
    preset_subdir = PRESET_SUBDIR
    preset_operator = ids.APPLY_MEASUREMENT_PRESET  # script.execute_preset in one undo step

    # script.execute_preset calls these before and after running the preset file (which sets the five
    # fields one by one): one live update instead of five.
    @staticmethod
    def reset_cb(_context, _filepath):
        hold_live_updates()

    @staticmethod
    def post_cb(context, _filepath):
        release_live_updates(context.scene)

    def draw(self, _context):
        folders = [str(SHIPPED_PRESETS)] + bpy.utils.preset_paths(PRESET_SUBDIR)
        self.path_menu(folders, self.preset_operator, filter_ext=lambda ext: ext.lower() == ".py",
                       display_name=lambda path: bpy.path.display_name(os.path.basename(path), title_case=False))


class ELLIMANN_OT_apply_measurement_preset(bpy.types.Operator):
    """Set the five measurements from a preset; with Live on the mannequin follows, in the same undo step"""

    bl_idname = ids.APPLY_MEASUREMENT_PRESET
    bl_label = "Apply Measurement Preset"
    bl_options = {"REGISTER", "UNDO", "INTERNAL"}  # script.execute_preset has no undo step of its own

    filepath: StringProperty(name="Preset", subtype="FILE_PATH", options={"HIDDEN", "SKIP_SAVE"},
                             description="The preset file (.py) to run")

    @classmethod
    def poll(cls, context):
        return hasattr(context.scene, "ellimann_synthesis")

    def execute(self, context):
        if not (self.filepath.lower().endswith(".py") and os.path.isfile(self.filepath)):
            self.report({"ERROR"}, f"No measurement preset at '{self.filepath}'")
            return {"CANCELLED"}
        try:
            bpy.ops.script.execute_preset(filepath=self.filepath, menu_idname=ids.MENU_MEASUREMENT_PRESETS)
        except RuntimeError as error:  # the preset ran part-way: FINISHED, so that one undo takes it back
            self.report({"ERROR"}, f"Preset '{os.path.basename(self.filepath)}' failed: {error}")
        return {"FINISHED"}


class ELLIMANN_OT_add_measurement_preset(AddPresetBase, bpy.types.Operator):
    """Save the five measurements as a preset (or remove the selected one of your own)"""

    bl_idname = ids.ADD_MEASUREMENT_PRESET
    bl_label = "Add Measurement Preset"
    preset_menu = ids.MENU_MEASUREMENT_PRESETS
    preset_subdir = PRESET_SUBDIR
    preset_defines = ["props = bpy.context.scene.ellimann_synthesis"]
    preset_values = [f"props.{attr}" for attr in FIELDS.values()]

    @classmethod
    def poll(cls, context):
        return hasattr(context.scene, "ellimann_synthesis")


classes = (ELLIMANN_PG_synthesis, ELLIMANN_OT_synthesize_mannequin, ELLIMANN_MT_measurement_presets,
           ELLIMANN_OT_apply_measurement_preset, ELLIMANN_OT_add_measurement_preset)
_register_classes, _unregister_classes = bpy.utils.register_classes_factory(classes)


def register():
    _register_classes()
    bpy.types.Scene.ellimann_synthesis = PointerProperty(type=ELLIMANN_PG_synthesis)
    for name in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if settle_restored not in handlers:
            handlers.append(settle_restored)


def unregister():
    for name in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if settle_restored in handlers:
            handlers.remove(settle_restored)
    if bpy.app.timers.is_registered(_settle_timer):
        bpy.app.timers.unregister(_settle_timer)
    _settling["scenes"].clear()
    del bpy.types.Scene.ellimann_synthesis
    _unregister_classes()
