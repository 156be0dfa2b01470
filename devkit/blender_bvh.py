"""A BVH clip through Blender's own importer (``import_anim.bvh``), for comparing ElliMann's reading with it: every
bone's posed head in each frame, in ElliMann's axes (the importer turning BVH's Y up into Z up, the character
facing -Y), in the file's units; the armature and its action are removed again."""

import os

import bpy
import numpy as np


def blender_heads(path):
    """(F, k, 3): each bone's head (file order) at each of the clip's frames, as Blender's importer shows them."""
    before = {o.as_pointer() for o in bpy.data.objects}
    actions = {a.as_pointer() for a in bpy.data.actions}
    scene = bpy.context.scene
    frame = scene.frame_current
    result = bpy.ops.import_anim.bvh(
        filepath=os.fspath(path),
        global_scale=1.0,
        use_fps_scale=False,
        update_scene_fps=False,
        update_scene_duration=False,
        rotate_mode="NATIVE",
        axis_forward="-Z",
        axis_up="Y",
    )
    try:
        assert result == {"FINISHED"}
        (rig,) = [o for o in bpy.data.objects if o.as_pointer() not in before and o.type == "ARMATURE"]
        first, last = (int(round(v)) for v in rig.animation_data.action.frame_range)
        world = np.array(rig.matrix_world)
        heads = []
        for number in range(first, last + 1):
            scene.frame_set(number)
            heads.append([(world @ np.append(np.array(b.head), 1.0))[:3] for b in rig.pose.bones])
        return np.array(heads)
    finally:
        for obj in [o for o in bpy.data.objects if o.as_pointer() not in before]:
            data = obj.data
            bpy.data.objects.remove(obj)
            if isinstance(data, bpy.types.Armature) and data.users == 0:
                bpy.data.armatures.remove(data)
        for action in [a for a in bpy.data.actions if a.as_pointer() not in actions]:
            bpy.data.actions.remove(action)
        scene.frame_set(frame)
