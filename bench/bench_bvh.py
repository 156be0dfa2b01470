"""BVH motion: a 2,000-frame Mixamo-named clip (devkit.clips) read and matched, retargeted and clamped onto the
Average RM by the core (numpy), written as .json frames and MJCF keyframes, against Blender's own importer
reading the same clip in the same run (what the Import BVH operator did before issue 27); the operator end to end;
and the memory a frame takes (tracemalloc, 600 frames against 200) beside the estimate that refuses long clips."""

import tempfile
import time
from pathlib import Path

from devkit import bvh, clips
from ellimann_addon.core.formats.bvh import read_bvh
from ellimann_addon.core.formats.table import write_file
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.pose.clip import clip_onto
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

FRAMES = 2000


def seconds(fn):
    start = time.perf_counter()
    result = fn()
    return time.perf_counter() - start, result


def run(quick=False):
    """``quick``: a 60-frame clip (checks that it runs)."""
    frames = 60 if quick else FRAMES
    average = Mannequin.load(REFERENCE_FOLDER / "average.json")
    folder = Path(tempfile.mkdtemp(prefix="ellimann-bench-bvh-"))
    clip = clips.convention_clip("mixamo", average.joints, frames=frames)
    path = bvh.write_bvh(folder / "clip.bvh", clip)
    reading, read = seconds(lambda: read_bvh(path))
    retargeting, onto = seconds(lambda: clip_onto(average, read.motion, read.match, name=read.name))
    to_json, _ = seconds(lambda: write_file(average, folder / "clip.json", frames=onto.poses))
    to_mjcf, _ = seconds(lambda: write_file(average, folder / "clip.xml", frames=onto.poses))
    core = reading + retargeting
    print(f"{frames} frames, {len(read.motion.names)} bones:")
    print(f"  read and matched (numpy)         {reading:6.2f} s")
    print(f"  retargeted and clamped (numpy)   {retargeting:6.2f} s ({1e3 * retargeting / frames:.2f} ms a frame)")
    print(f"  written: .json {to_json:.2f} s, MJCF keyframes {to_mjcf:.2f} s")
    blender = _blender(path, average)
    if blender is not None:
        importer, operator = blender
        print(
            f"  Blender's importer on the same clip {importer:6.2f} s: the core reads and retargets in "
            f"{core / importer:.2f}x its time"
        )
        print(f"  Import BVH operator end to end   {operator:6.2f} s")
    measured, estimated = clips.bytes_per_frame("mixamo", average, folder)
    print(
        f"  memory a frame (read, retarget, .json): {measured / 1e3:.1f} KB measured, "
        f"{estimated / 1e3:.1f} KB estimated"
    )


def _blender(path, average):
    """(seconds of Blender's importer, seconds of the Import BVH operator) on the clip, or None without bpy."""
    try:
        import bpy
    except ImportError:
        return None
    import ellimann_addon
    from devkit.blender_bvh import blender_heads
    from ellimann_addon.blender.services.scene import add_mannequin

    ellimann_addon.register()
    try:
        bpy.ops.wm.read_homefile(use_empty=True)
        importer, _ = seconds(lambda: blender_heads(path))
        collection = add_mannequin(average)
        bpy.context.view_layer.objects.active = next(iter(collection.objects))
        bpy.ops.ellimann.add_armature()
        operator, _ = seconds(lambda: bpy.ops.ellimann.import_bvh(filepath=str(path)))
        return importer, operator
    finally:
        ellimann_addon.unregister()
