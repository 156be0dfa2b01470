"""Blender's rows of the format table (``core.formats.table``): .blend and .glb (one writer for both) and the FBX
avatar, bound to them when this module is loaded (the core never imports the Blender layer). At rest .blend and
.glb are ``files.write_mannequin``, posed ``posing.write_posed``: one mannequin, its skin and its poses, every .blend
and .glb from one empty scene. The FBX avatar is ``fbx.write_fbx``: the skin alone on its bones, as the job's
avatar options (``core.formats.avatar.AvatarOptions``) ask."""

from ...core.errors import ElliMannError
from ...core.formats.avatar import AvatarOptions
from ...core.formats.table import AVATAR_FORMATS, SCENE_FORMATS, bind_writer
from ...core.pose.standard import WALK_FPS
from .fbx import write_fbx
from .files import write_mannequin
from .posing import write_posed


def write_blender_files(mannequin, paths, *, cushions=False, skin=None, measured=None, frames=None, fps=None, **_):
    """Write ``mannequin`` (with its core ``skin``; in ``frames`` at ``fps`` when posed) to every .blend and .glb
    of ``paths``; ``measured``: its rest m_T ({He..Hi: cm}) for the .glb's extras, if the caller holds it."""
    if frames is None:
        return write_mannequin(mannequin, paths, measured, cushions, skin=skin)
    return write_posed(mannequin, frames, paths, cushions, fps or WALK_FPS, measured, skin=skin)


def write_avatar_files(mannequin, paths, *, skin=None, avatar=None, **_):
    """Write the avatar of ``mannequin`` and its ``skin`` to every .fbx of ``paths`` (``avatar``: its
    AvatarOptions, default an A-pose with SMPL's names under 70k triangles that measures the mannequin's targets);
    the job's pose, if any, is the avatar's (``avatar.pose``: the job decides it). Each FbxAvatar is told to
    ``avatar.told``."""
    if skin is None:
        raise ElliMannError(f"{paths[0]}: an FBX avatar is the mannequin's skin: ask for one (--skin)")
    avatar = (avatar or AvatarOptions()).checked()
    for path in paths:
        written = write_fbx(
            path,
            mannequin,
            skin,
            request=avatar.request,
            pose=avatar.pose,
            naming=avatar.naming,
            pieces=avatar.proxy,
            max_triangles=avatar.max_triangles,
        )
        if avatar.told is not None:
            avatar.told(written)
    return list(paths)


bind_writer(SCENE_FORMATS, write_blender_files)
bind_writer(AVATAR_FORMATS, write_avatar_files)
