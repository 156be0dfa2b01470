"""How a mannequin's skin was made, as its file records it: the versioned ``skin`` section (voxel, blend, method),
so that the skin can be made again from the pieces (``ellimann pose IN.json --skin``), checked on load like the
other sections. The skin itself is ``core.skin`` (floor 5), whose settings read and write this section
(``core.skin.settings.SkinSettings.to_dict`` / ``from_dict``).

A record is a recipe, not a result: it stays true whatever is done to the pieces (the same pieces give the same
skin, bit for bit), so it records no measurement.
"""

import math

from ..errors import MannequinError, Problem
from ..settings import BLEND_RANGE, VOXEL_RANGE_MM
from .field_checks import json_type, short

SKIN_VERSION = 1  # of the ``skin`` section
FIELDS = ("version", "voxel_mm", "blend", "method")


def skin_record_problems(data):
    """Problems of a ``skin`` section: an object with version SKIN_VERSION, voxel_mm and blend (numbers within
    their ranges) and method (a string, what the skin was made by)."""

    def problem(field, message):
        return [Problem("", f"skin.{field}" if field else "skin", message)]

    if not isinstance(data, dict):
        return problem("", f"must be an object ({', '.join(FIELDS)}) or absent, got {json_type(data)}")
    version = data.get("version")
    if isinstance(version, bool) or version != SKIN_VERSION:
        return problem("version", f"is {short(version)}; this ElliMann reads skin version {SKIN_VERSION}")
    out = []
    for field, (low, high) in (("voxel_mm", VOXEL_RANGE_MM), ("blend", BLEND_RANGE)):
        value = data.get(field)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            out += problem(field, f"must be a number from {low:g} to {high:g}, got {short(value)}")
        elif not low <= value <= high:
            out += problem(field, f"is {value:g}; accepted range {low:g} to {high:g}")
    if not isinstance(data.get("method"), str):
        out += problem("method", f"must be a string (how the skin was made), got {json_type(data.get('method'))}")
    unknown = [key for key in data if key not in FIELDS]
    if unknown:
        out += problem(short(unknown[0]), f"is not a field of the skin section ({', '.join(FIELDS)})")
    return out


def skin_record_from_dict(data):
    """The ``skin`` section of a mannequin file (None if absent) as a plain dict of FIELDS; MannequinError naming
    the field otherwise."""
    if data is None:
        return None
    problems = skin_record_problems(data)
    if problems:
        raise MannequinError(problems)
    return {key: float(data[key]) if key in ("voxel_mm", "blend") else data[key] for key in FIELDS}
