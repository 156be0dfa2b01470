"""Blender's rows of the format table (``core.formats.table``: .blend and .glb): one writer for both, bound to them
when this module is loaded (the core never imports the Blender layer). At rest it is ``files.write_mannequin``,
posed ``posing.write_posed``: one mannequin, its skin and its poses, every .blend and .glb from one empty scene."""

from ...core.formats.table import BLENDER_FORMATS, bind_writer
from ...core.pose.standard import WALK_FPS
from .files import write_mannequin
from .posing import write_posed


def write_blender_files(mannequin, paths, *, cushions=False, skin=None, measured=None, frames=None, fps=None):
    """Write ``mannequin`` (with its core ``skin``; in ``frames`` at ``fps`` when posed) to every .blend and .glb
    of ``paths``; ``measured``: its rest m_T ({He..Hi: cm}) for the .glb's extras, if the caller holds it."""
    if frames is None:
        return write_mannequin(mannequin, paths, measured, cushions, skin=skin)
    return write_posed(mannequin, frames, paths, cushions, fps or WALK_FPS, measured, skin=skin)


bind_writer(BLENDER_FORMATS, write_blender_files)
