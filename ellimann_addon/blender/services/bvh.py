"""Reading a BVH clip with Blender's own importer (``import_anim.bvh``) into ``core.pose.retarget.SourceMotion``.

The bone names are read from the file's HIERARCHY first (a few lines of text), so a clip with no bone
the name map knows is refused before anything enters the scene. The importer then builds a temporary
armature (BVH's Y-up axes turned into Blender's Z-up, the character facing -Y as ElliMann's do); each
frame's bone matrices are sampled and the armature, its action and its data are removed again, the
scene back at its frame and its active object.
"""

import os
import re

import bpy
import numpy as np

from ...core.errors import ElliMannError
from ...core.geometry.frames import project_to_rotation
from ...core.pose.retarget import SourceMotion
from .chatter import blender_output

BONE_LINE = re.compile(r"^\s*(ROOT|JOINT)\s+(.+?)\s*$")
FRAME_TIME_LINE = re.compile(r"^\s*Frame Time:\s*([0-9.eE+-]+)\s*$")


def bvh_header(path):
    """(bone names, frame time s) from a BVH file's text; ElliMannError naming the file if it is not one."""
    path = os.fspath(path)
    try:
        with open(path, encoding="utf-8", errors="replace") as stream:
            text = stream.read()
    except OSError as error:
        raise ElliMannError(f"filepath: cannot read {path}: {error.strerror or error}") from error
    lines = text.splitlines()
    if not lines or lines[0].strip() != "HIERARCHY" or "MOTION" not in (line.strip() for line in lines):
        raise ElliMannError(f"filepath: {path} is not a BVH clip (no HIERARCHY and MOTION sections)")
    names = [match.group(2) for match in map(BONE_LINE.match, lines) if match]
    frame_time = next((float(m.group(1)) for m in map(FRAME_TIME_LINE.match, lines) if m), 0.0)
    if not names or not frame_time > 0:
        raise ElliMannError(f"filepath: {path} has no bones or no positive Frame Time")
    return names, frame_time


def sample_bvh(path):
    """The clip as a SourceMotion (every frame, ElliMann's axes), through Blender's importer; the scene is
    left as it was. ElliMannError if the importer fails."""
    path = os.fspath(path)
    _, frame_time = bvh_header(path)
    scene = bpy.context.scene
    view_layer = bpy.context.view_layer
    frame, active = scene.frame_current, view_layer.objects.active
    selected = [o for o in view_layer.objects if o.select_get()]
    before = {o.as_pointer() for o in bpy.data.objects}
    actions_before = {a.as_pointer() for a in bpy.data.actions}
    try:
        with blender_output():
            result = bpy.ops.import_anim.bvh(
                filepath=path,
                global_scale=1.0,
                use_fps_scale=False,
                update_scene_fps=False,
                update_scene_duration=False,
                rotate_mode="NATIVE",
                axis_forward="-Z",
                axis_up="Y",
            )
    except RuntimeError as error:
        _remove_new(before, actions_before)
        raise ElliMannError(f"filepath: Blender's BVH importer refused {path}: {error}") from error
    try:
        imported = [o for o in bpy.data.objects if o.as_pointer() not in before and o.type == "ARMATURE"]
        if result != {"FINISHED"} or not imported:
            raise ElliMannError(f"filepath: Blender's BVH importer made no armature from {path}")
        return _sampled(imported[0], scene, frame_time)
    finally:
        _remove_new(before, actions_before)
        scene.frame_set(frame)
        for obj in view_layer.objects:
            obj.select_set(obj in selected)
        view_layer.objects.active = active


def _sampled(source, scene, frame_time):
    bones = list(source.pose.bones)
    world = np.array(source.matrix_world)
    rest = np.array([np.array(b.bone.matrix_local) for b in bones])
    rest_inverse = np.linalg.inv(rest)
    action = source.animation_data.action if source.animation_data else None
    first, last = (int(round(v)) for v in action.frame_range) if action else (1, 1)
    rotations, roots = [], []
    root = next(i for i, b in enumerate(bones) if b.parent is None)
    for frame in range(first, last + 1):
        scene.frame_set(frame)
        posed = np.array([np.array(b.matrix) for b in bones])
        motion = world @ posed @ rest_inverse  # rest -> posed, world space
        rotations.append(project_to_rotation(motion[:, :3, :3]))  # an importer's global_scale leaves a scale
        roots.append((world @ posed[root])[:3, 3])
    heads = (rest[:, :3, 3] @ world[:3, :3].T) + world[:3, 3]
    return SourceMotion([b.name for b in bones], heads, np.array(rotations), np.array(roots), 1.0 / frame_time)


def _remove_new(objects_before, actions_before):
    for obj in [o for o in bpy.data.objects if o.as_pointer() not in objects_before]:
        data = obj.data
        bpy.data.objects.remove(obj)
        if isinstance(data, bpy.types.Armature) and data.users == 0:
            bpy.data.armatures.remove(data)
    for action in [a for a in bpy.data.actions if a.as_pointer() not in actions_before]:
        bpy.data.actions.remove(action)
