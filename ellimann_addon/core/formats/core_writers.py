"""Mannequin files the core writes without Blender: OBJ (Y up), ElliMann's JSON and MJCF (MuJoCo's XML).

Formats are named by what a user types (``--format json,mjcf``); each has one file extension (``core.formats.table``).
"""

import os

from ..errors import ElliMannError
from .mjcf import write_mjcf
from .obj import write_obj
from .table import CORE_FORMATS, FORMATS, format_of

EXTENSIONS = {name: FORMATS[name].extension for name in CORE_FORMATS}  # format -> file extension (core.formats.table)


def core_format(path):
    """The core format a path's extension names ("obj", "json", "mjcf"), or None."""
    kind = format_of(path)
    return kind.name if kind is not None and not kind.needs_blender else None


def write_core_file(mannequin, path, cushions=False):
    """Write ``mannequin`` to an .obj, .json or .xml (MJCF), atomically; ``cushions``: cushion pairs as their hull
    meshes (OBJ) or convex mesh geoms (MJCF)."""
    kind = core_format(path)
    if kind == "json":
        mannequin.save(path)
    elif kind == "obj":
        write_obj(mannequin, path, cushions=cushions)
    elif kind == "mjcf":
        write_mjcf(mannequin, path, cushions=cushions)
    else:
        raise ElliMannError(f"path: {os.fspath(path)!r} is not an .obj, .json or .xml file")
    return os.fspath(path)
