"""Mannequin files the core writes without Blender: OBJ (Y up), ElliMann's JSON and MJCF (MuJoCo's XML).

Formats are named by what a user types (``--format json,mjcf``); each has one file extension (``core.formats.table``).
"""

import os

import numpy as np

from ..errors import ElliMannError
from .mjcf import write_mjcf
from .obj import write_obj, write_skin_obj
from .table import CORE_FORMATS, FORMATS, format_of

EXTENSIONS = {name: FORMATS[name].extension for name in CORE_FORMATS}  # format -> file extension (core.formats.table)


def core_format(path):
    """The core format a path's extension names ("obj", "json", "mjcf"), or None."""
    kind = format_of(path)
    return kind.name if kind is not None and not kind.needs_blender else None


def write_core_file(mannequin, path, cushions=False, skin=None):
    """Write ``mannequin`` to an .obj, .json or .xml (MJCF), atomically; ``cushions``: cushion pairs as their hull
    meshes (OBJ) or convex mesh geoms (MJCF). ``skin`` (a ``core.skin.surface.Skin`` of these pieces): the .obj
    holds the skin alone, the .json records how it was made (its ``skin`` section), the MJCF draws it over the
    pieces."""
    kind = core_format(path)
    mannequin = with_skin_record(mannequin, skin)
    if kind == "json":
        mannequin.save(path)
    elif kind == "obj" and skin is not None:
        write_skin_obj(skin, path)
    elif kind == "obj":
        write_obj(mannequin, path, cushions=cushions)
    elif kind == "mjcf":
        write_mjcf(mannequin, path, cushions=cushions, skin=skin)
    else:
        raise ElliMannError(f"path: {os.fspath(path)!r} is not an .obj, .json or .xml file")
    return os.fspath(path)


def with_skin_record(mannequin, skin):
    """``mannequin`` recording how ``skin`` was made (its file's ``skin`` section); ElliMannError if the skin was
    made from other pieces (a caller's mistake: the file would hold a skin its pieces do not make)."""
    if skin is None:
        return mannequin
    made_from = skin.mannequin
    if made_from is not mannequin and not all(
        np.array_equal(getattr(made_from, field), getattr(mannequin, field))
        for field in ("rotation", "center", "semi_axes")
    ):
        raise ElliMannError(f"skin: made from other pieces than those of '{mannequin.name}'")
    return mannequin.copy(skin=skin.settings.to_dict())
