"""Posed mannequins in Blender files: the armature, every piece bound to its bone, in a pose or moving.

``write_posed`` is what the command line calls for ``--pose`` with .blend and .glb outputs
(``cli.writing.write_posed``; .json, MJCF and .obj come from ``core.formats.posed_files``): from an empty scene,
the rest mannequin, its armature (``services.rig``), one pose or a motion as an action on the timeline (the walk,
looping; a clip, playing once), then each file through ``services.files`` (atomically). A .blend opens posed (or
playing the motion); a .glb is a skinned glTF in that pose with the motion as an animation. With a skin, the skin
is bound to the armature too and the pieces stay beside it as colliders.
"""

import bpy

from ...core.errors import ElliMannError
from ...core.pose.standard import MOTIONS, WALK_FPS
from .files import checked_paths, write_with_skin
from .rig import apply_motion, apply_pose, build_rig, check_rig
from .scene import add_mannequin, empty_scene


def write_posed(mannequin, frames, paths, cushions=False, fps=WALK_FPS, measured=None, skin=None):
    """Write ``mannequin`` (at rest, with joints) posed by ``frames`` (core Poses, already within the limits:
    one for a still pose, several for a motion at ``fps``: the walk loops, a clip named after its file plays
    once) to every .blend and .glb in ``paths``;
    ``measured``: its rest m_T ({key: cm}) for the .glb's extras, if the caller holds it; ``skin``: its core Skin
    at rest, bound to the armature beside the pieces (``services.files.write_with_skin``).

    Raises ElliMannError before anything is written for a path of another kind, no frames, or a mannequin
    that cannot be rigged (no joints, a part without a bone). Returns the paths.
    """
    paths = checked_paths(paths)
    if not frames:
        raise ElliMannError("pose: no frames to write")
    check_rig(mannequin)
    if not paths:
        return paths
    scene = empty_scene()
    collection = add_mannequin(mannequin, cushions=cushions)
    rig = build_rig(collection, mannequin)
    if len(frames) == 1:
        apply_pose(rig, frames[0])
    else:
        name = frames[0].name.rsplit(" ", 1)[0] if frames[0].name else "motion"
        apply_motion(rig, frames, f"{collection.name} {name}", loop=name in MOTIONS)
        rate = fps or WALK_FPS
        scene.render.fps = max(1, int(round(rate)))
        scene.render.fps_base = scene.render.fps / rate
        scene.frame_start, scene.frame_end = 1, len(frames)
        scene.frame_set(1)
    bpy.context.view_layer.update()
    write_with_skin(paths, collection, mannequin, measured, skin)
    return paths
