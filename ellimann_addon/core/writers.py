"""Mannequin files the core writes without Blender: ElliMann's JSON and MJCF (MuJoCo's XML).

Formats are named by what a user types (``--format json,mjcf``); each has one file extension.
"""

import os

from .errors import ElliMannError
from .export_mjcf import write_mjcf

EXTENSIONS = {"json": "json", "mjcf": "xml"}  # format -> file extension


def core_format(path):
    """The core format a path's extension names ("json", "mjcf"), or None."""
    extension = os.path.splitext(os.fspath(path))[1].lower().lstrip(".")
    return next((kind for kind, ext in EXTENSIONS.items() if ext == extension), None)


def write_core_file(mannequin, path, cushions=False):
    """Write ``mannequin`` to a .json or .xml (MJCF; ``cushions``: cushion pairs as convex mesh geoms), atomically."""
    kind = core_format(path)
    if kind == "json":
        mannequin.save(path)
    elif kind == "mjcf":
        write_mjcf(mannequin, path, cushions=cushions)
    else:
        raise ElliMannError(f"path: {os.fspath(path)!r} is not a .json or .xml file")
    return os.fspath(path)
