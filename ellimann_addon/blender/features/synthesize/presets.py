"""Measurement presets of the Synthesize feature (Blender's preset system).

The five female RMs, the ten mannequins of the paper's Table 2.5, the five male RMs and the user's own (each also sets
the reference set it belongs to): the shipped ones are read from ``preset_files/`` beside this module, the user's are
saved in Blender's user preset folder. A preset sets five fields but makes one live update (the menu's ``reset_cb`` /
``post_cb`` hold it back), and the menu runs it through ``ELLIMANN_OT_apply_measurement_preset``, so that fields and
mannequin change in one undo step (Blender's ``script.execute_preset`` makes none).
"""

import os
import pathlib

import bpy
from bl_operators.presets import AddPresetBase
from bpy.props import StringProperty

from ... import ids
from .live import hold_live_updates, release_live_updates
from .request import FIELDS

PRESET_SUBDIR = "ellimann/synthesis"
SHIPPED_PRESETS = pathlib.Path(__file__).resolve().parent / "preset_files"


class ELLIMANN_MT_measurement_presets(bpy.types.Menu):
    """Measurements of the female and male Reference Mannequins, the paper's Table 2.5 and your own presets"""

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
        self.path_menu(
            folders,
            self.preset_operator,
            filter_ext=lambda ext: ext.lower() == ".py",
            display_name=lambda path: bpy.path.display_name(os.path.basename(path), title_case=False),
        )


class ELLIMANN_OT_apply_measurement_preset(bpy.types.Operator):
    """Set the five measurements from a preset; with Live on the mannequin follows, in the same undo step"""

    bl_idname = ids.APPLY_MEASUREMENT_PRESET
    bl_label = "Apply Measurement Preset"
    bl_options = {"REGISTER", "UNDO", "INTERNAL"}  # script.execute_preset has no undo step of its own

    filepath: StringProperty(
        name="Preset", subtype="FILE_PATH", options={"HIDDEN", "SKIP_SAVE"}, description="The preset file (.py) to run"
    )

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
    """Save the five measurements and the reference set as a preset (or remove the selected one of your own)"""

    bl_idname = ids.ADD_MEASUREMENT_PRESET
    bl_label = "Add Measurement Preset"
    preset_menu = ids.MENU_MEASUREMENT_PRESETS
    preset_subdir = PRESET_SUBDIR
    preset_defines = ["props = bpy.context.scene.ellimann_synthesis"]
    preset_values = [f"props.{attr}" for attr in FIELDS.values()] + ["props.reference_set"]

    @classmethod
    def poll(cls, context):
        return hasattr(context.scene, "ellimann_synthesis")


classes = (ELLIMANN_MT_measurement_presets, ELLIMANN_OT_apply_measurement_preset, ELLIMANN_OT_add_measurement_preset)
