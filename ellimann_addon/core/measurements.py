"""The measurements ElliMann takes, in one table: for each, its key (what files, the command line and the reports
say), its label, its unit, whether it is a girth (the perimeter of a section's convex hull: a tape) or a length,
where it is taken (its definition's page), the plausible values a request may ask, the panel's starting value, ISO
20685's allowance (how far two ways of measuring one body may differ) and how it is written. The command line, the
panels, the reports and the body measurer read it; the names below are made from it.

The five are the paper's (m_T, Section 2.3.5: He, Sh, Br, Wa, Hi); the six more are ISO 8559-1's most used beyond
them (docs/measurements.md). Every value is in centimetres.
"""

from dataclasses import dataclass


@dataclass(frozen=True)
class Measurement:
    key: str  # "He", "neck"
    label: str  # "Height", "Neck girth"
    girth: bool  # a tape round a section (its convex hull's perimeter), else a length
    where: str  # where it is taken, in a phrase; its whole definition: ``page``
    limits: tuple  # (low, high) cm: a request outside is refused (inside but outside a set's range: a warning)
    allowance: float  # ISO 20685 (cm)
    default: float | None = None  # the panel's starting value (the female Average RM's); the five's: the set's RM
    five: bool = False  # one of the paper's five (m_T)
    unit: str = "cm"
    decimals: int = 2  # as a line writes it

    page = "docs/measurements.md"  # where every definition is written out, with a picture of where each is taken


TABLE = (
    Measurement("He", "Height", False, "the lowest point to the highest", (50.0, 250.0), 0.4, five=True),
    Measurement(
        "Sh", "Shoulder width", False, "across the section at the shoulder height", (10.0, 100.0), 0.4, five=True
    ),
    Measurement("Br", "Breast perimeter", True, "the section at the bust height", (30.0, 300.0), 0.9, five=True),
    Measurement("Wa", "Waist perimeter", True, "the section at the waist height", (30.0, 300.0), 0.9, five=True),
    Measurement("Hi", "Hip perimeter", True, "the section at the hip height", (30.0, 300.0), 0.9, five=True),
    Measurement("neck", "Neck girth", True, "the smallest section square to the neck", (15.0, 80.0), 0.9, 24.1),
    Measurement(
        "upper_arm", "Upper-arm girth", True, "across the arm a quarter down from the shoulder", (10.0, 80.0), 0.9, 23.6
    ),
    Measurement("thigh", "Thigh girth", True, "one leg just below the crotch", (20.0, 140.0), 0.9, 56.0),
    Measurement("calf", "Calf girth", True, "one leg's largest below the knee", (15.0, 90.0), 0.9, 42.6),
    Measurement("crotch_height", "Crotch height", False, "the floor to the crotch", (20.0, 130.0), 0.4, 72.0),
    Measurement("arm_length", "Arm length", False, "the shoulder point to the fingertip", (20.0, 120.0), 0.4, 57.8),
)
BY_KEY = {row.key: row for row in TABLE}
MEASUREMENTS = tuple(row.key for row in TABLE if row.five)  # He, Sh, Br, Wa, Hi
EXTRA_MEASUREMENTS = tuple(row.key for row in TABLE if not row.five)  # neck, upper_arm, thigh, calf, crotch_height, ...
ALL_MEASUREMENTS = MEASUREMENTS + EXTRA_MEASUREMENTS
MEASUREMENT_LABELS = {row.key: row.label for row in TABLE}
ABSURD_LIMITS = {key: BY_KEY[key].limits for key in MEASUREMENTS}  # a request's five (a set may carry its own)
EXTRA_ABSURD_LIMITS = {key: BY_KEY[key].limits for key in EXTRA_MEASUREMENTS}
EXTRA_DEFAULTS = {key: BY_KEY[key].default for key in EXTRA_MEASUREMENTS}
EXTRA_GIRTHS = tuple(key for key in EXTRA_MEASUREMENTS if BY_KEY[key].girth)
ISO_ALLOWANCE = {row.key: row.allowance for row in TABLE}


def measurement_line(values, keys=None):
    """ "He 165.00, Sh 41.50, Br 101.25, Wa 82.75, Hi 117.50, neck 33.99": the one way measurements (m_T, a
    request, a skin's, a body's) are written in a line (command line, status bar, operator reports). ``values``: a
    dict keyed by the table's keys, or the five's numbers in order; ``keys``: which (default: every one ``values``
    holds, in the table's order)."""
    if not isinstance(values, dict):
        values = dict(zip(MEASUREMENTS, values))
    keys = [key for key in ALL_MEASUREMENTS if key in values] if keys is None else list(keys)
    return ", ".join(f"{key} {float(values[key]):.{BY_KEY[key].decimals}f}" for key in keys)
