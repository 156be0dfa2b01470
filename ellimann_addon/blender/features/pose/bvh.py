"""Import BVH Motion: a clip read and matched by the core (``core.formats.bvh``: numpy, the same path as the command
line's ``--pose clip.bvh``), retargeted onto the active mannequin's armature as an action; what was not placed,
the joints that will not bend, the clamps per joint and where the feet went are reported and shown in the panel."""

import os

import bpy
from bpy.props import StringProperty
from bpy_extras.io_utils import ImportHelper

from ....core.errors import ElliMannError
from ....core.formats.bvh import read_bvh
from ....core.pose.clip import clip_onto
from ... import ids
from ...bridge.convert import rig_object
from ...services.rig import apply_motion
from ..base import MannequinOperator, OperatorError, mannequin_or_cancel, plural
from .operators import has_rig

SHOWN_LINES = 12  # lines of the last import the panel shows (the Info log has them in full)


def motion_onto(collection, path, rig="auto", keep_on_floor=False, progress=lambda step: None):
    """(the clip read, its ``core.pose.clip.ClipOnMannequin`` on a mannequin collection); ElliMannError (nothing
    changed) for a file that is not a clip ElliMann can use or a mannequin without joints. ``progress(1)`` once
    the clip is read."""
    mannequin = mannequin_or_cancel(collection)
    if mannequin.joints is None:
        raise ElliMannError(f"joints: '{collection.name}' has no joints (rig it again: Add Armature)")
    clip = read_bvh(path, rig)
    progress(1)
    return clip, clip_onto(mannequin, clip.motion, clip.match, keep_on_floor, clip.name)


def import_lines(clip, onto):
    """(warnings, information): what the import says beyond its one-line result."""
    warnings = [line for line in [clip.match.stiff_line()] if line]
    warnings += onto.clamp_lines()
    hint = "; Keep on Floor holds it on the floor" if not onto.held else ""
    return warnings, [*clip.lines()[1:], onto.floor_line(hint)]


def panel_lines(clip, onto):
    """The outcome of an import, short enough for the sidebar: what will not bend, each clamp, what was not
    placed, the joints without a bone, where the feet went."""
    match, lines = clip.match, []
    lines += [f"will not bend: {joint} (between {a} and {b})" for joint, (a, b) in match.stiff.items()]
    lines += [
        f"{c.joint} {c.axis}: {c.frames}/{c.total} frames, worst {c.worst:.0f}\u00b0 (frame {c.frame}), "
        f"range {c.low:.0f} to {c.high:.0f}"
        for c in onto.clamps
        if not c.slight
    ]
    lines += [f"not placed: {', '.join(match.unplaced)}"] if match.unplaced else []
    lines += [f"no bone: {', '.join(match.unsourced)}"] if match.unsourced else []
    low, high = onto.lowest.min(), onto.lowest.max()
    feet = f"feet: {100 * low:+.1f} to {100 * high:+.1f} cm from the floor"
    return lines + [feet + (" (held on it)" if onto.held else "")]


class ELLIMANN_OT_import_bvh(MannequinOperator, ImportHelper, bpy.types.Operator):
    """Import a BVH clip (any common rig's bone names) onto the active mannequin's armature, clamping passed limits"""

    bl_idname = ids.IMPORT_BVH
    bl_label = "Import BVH Motion"
    bl_options = {"REGISTER", "UNDO"}
    OBJECT_MODE_ONLY = False

    filename_ext = ".bvh"
    filter_glob: StringProperty(default="*.bvh", options={"HIDDEN"}, description="Files shown in the browser")

    @classmethod
    def poll(cls, context):
        return hasattr(context.scene, "ellimann_pose") and has_rig(context)

    def run(self, context, collection):
        props, window_manager = context.scene.ellimann_pose, context.window_manager
        window_manager.progress_begin(0, 3)  # read, retargeted, baked
        try:
            try:
                clip, onto = motion_onto(
                    collection, self.filepath, props.rig, props.keep_on_floor, window_manager.progress_update
                )
            except ElliMannError as error:
                raise OperatorError(f"Cannot import onto '{collection.name}': {error}") from error
            window_manager.progress_update(2)
            name = os.path.splitext(clip.name)[0]
            action = apply_motion(rig_object(collection), onto.poses, name)
        finally:
            window_manager.progress_end()
        scene = context.scene
        scene.render.fps = max(1, round(clip.motion.fps))
        scene.render.fps_base = scene.render.fps / clip.motion.fps
        scene.frame_start, scene.frame_end = 1, len(onto.poses)
        scene.frame_set(1)
        warnings, information = import_lines(clip, onto)
        for line in information:
            self.report({"INFO"}, line)
        for line in warnings:
            self.report({"WARNING"}, line)
        stiff = ", ".join(clip.match.stiff)
        clamped = {c.joint for c in onto.clamps if not c.slight}
        outcome = (
            f"{len(onto.poses)} frames, {clip.match.label}"
            + (f"; {plural(len(clamped), 'joint')} clamped" if clamped else "")
            + (f"; will not bend: {stiff}" if stiff else "")
        )
        props.status = "\n".join([f"{name}: {outcome}", *panel_lines(clip, onto)][:SHOWN_LINES])
        self.report(
            {"WARNING" if warnings else "INFO"},
            f"Imported '{name}' onto '{collection.name}' as action '{action.name}': {outcome}",
        )
        return {"FINISHED"}


classes = (ELLIMANN_OT_import_bvh,)
