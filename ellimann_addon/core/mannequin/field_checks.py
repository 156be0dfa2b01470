"""What a mannequin file's fields may hold, and how a message shows what they held instead: target
measurements (within the limits a synthesis request must meet), section heights, short reprs of hostile
values."""

import math

from ..constants import SECTION_FRACTIONS
from ..errors import Problem
from ..measurements import ABSURD_LIMITS, MEASUREMENTS


def measurement_problems(measurements):
    """Problems of target measurements: None, or a dict of some of He, Sh, Br, Wa, Hi in cm, each a number
    within ``ABSURD_LIMITS`` (the limits a synthesis request must meet)."""
    if measurements is None:
        return []
    if not isinstance(measurements, dict):
        return [
            Problem(
                "",
                "measurements",
                f"must be a dict of He, Sh, Br, Wa, Hi in cm (or None), got {json_type(measurements)}",
            )
        ]
    out = []
    for key, value in measurements.items():
        if key not in MEASUREMENTS:
            out.append(
                Problem(
                    "", "measurements", f"{short(key)} is not a measurement; expected some of {', '.join(MEASUREMENTS)}"
                )
            )
            continue
        low, high = ABSURD_LIMITS[key]
        accepted = f"accepted range {low:g}-{high:g} cm"
        if not _positive_number(value):
            out.append(Problem("", "measurements", f"{key}={short(value)} is not a positive measurement ({accepted})"))
        elif not low <= value <= high:
            out.append(Problem("", "measurements", f"{key}={value:g} cm is not a plausible value ({accepted})"))
    return out


def section_fraction_problems(fractions):
    """Problems of section heights: a dict of exactly Sh, Br, Wa, Hi, each a fraction of He, with
    0 < Hi < Wa < Br < 1 and 0 < Sh < 1 (the girth blend of exact mode needs the girths in that order)."""
    field_name = "section_fractions"
    if not isinstance(fractions, dict) or set(fractions) != set(SECTION_FRACTIONS):
        return [
            Problem(
                "",
                field_name,
                f"must hold exactly {', '.join(SECTION_FRACTIONS)} (fractions of He), got {short(fractions)}",
            )
        ]
    for key in SECTION_FRACTIONS:
        value = fractions[key]
        if not _positive_number(value) or value >= 1.0:
            return [Problem("", field_name, f"{key}={short(value)} must be a fraction of He in (0, 1)")]
    if not fractions["Hi"] < fractions["Wa"] < fractions["Br"]:
        return [
            Problem(
                "",
                field_name,
                f"must have Hi < Wa < Br, got Hi {fractions['Hi']:g}, Wa {fractions['Wa']:g}, Br {fractions['Br']:g}",
            )
        ]
    return []


def _positive_number(value):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return math.isfinite(value) and value > 0
    except OverflowError:  # an int beyond float's range
        return False


def json_type(value):
    """What a JSON value is, for messages: 'a list', 'a string', 'null', ..."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, float)):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, (list, tuple)):
        return "a list"
    if isinstance(value, dict):
        return "an object"
    return f"a {type(value).__name__}"


def short(value, limit=60):
    """repr of ``value`` cut to ``limit`` characters (a hostile file's values may be huge or deeply nested)."""
    try:
        text = repr(value)
    except (RecursionError, ValueError):  # ValueError: an int too long to print
        text = f"a {type(value).__name__}"
    return text if len(text) <= limit else text[: limit - 3] + "..."
