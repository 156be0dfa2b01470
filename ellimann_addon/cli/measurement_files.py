"""``measure --write-measurements OUT``: the measurements ``measure`` shows, written back for the pattern tools
(``core.sizing.writers``), the format by OUT's extension as every output of ElliMann's: .vit (a Seamly2D /
Valentina individual measurements file), .json (a FreeSewing measurements set), .csv (a size chart's row). One
option rather than one per format: a file's format is decided by its extension everywhere else too (``-o``), and
``measure`` reads no .vit or .csv that could be confused with one written."""

import math
import os

from ..core.measurements import ALL_MEASUREMENTS
from . import output
from .output import PROG, UsageError
from .writing import writing

FORMATS = {
    ".vit": "a Seamly2D / Valentina individual measurements file",
    ".json": "a FreeSewing measurements set (mm, as the format defines)",
    ".csv": "a size chart's row",
}
UNITS = ("cm", "mm", "inch")


def add_write_options(parser):
    listed = ", ".join(f"{extension} ({what})" for extension, what in FORMATS.items())
    parser.add_argument(
        "--write-measurements",
        metavar="OUT",
        help=f"also write the measurements shown (a .json with a skin: its skin's) for pattern tools, the format by "
        f"OUT's extension: {listed}; docs/formats/measurement_files.md",
    )
    parser.add_argument(
        "--write-unit",
        choices=UNITS,
        default="cm",
        help="the unit of a .vit or .csv written (default cm; a FreeSewing set is in mm by its definition)",
    )


def check_write(args):
    """UsageError (one line) for an OUT whose extension names no measurement file, or that is the file measured,
    before anything is measured."""
    path = args.write_measurements
    if path is None:
        return
    extension = os.path.splitext(path)[1].lower()
    if extension not in FORMATS:
        raise UsageError(f"--write-measurements {path}: must end in {', '.join(FORMATS)} (the format by its extension)")
    if os.path.abspath(path) == os.path.abspath(args.file):
        raise UsageError(f"--write-measurements {path}: is the file measured; write to another")
    if args.write_unit != "cm" and extension == ".json":
        raise UsageError(f"--write-unit {args.write_unit}: a FreeSewing set is in mm by its definition; drop it")


def write_measurements(args, values, name, sex=None):
    """Write ``values`` ({key: cm}; those not taken left out) to --write-measurements, if given, and say so."""
    path = args.write_measurements
    if path is None:
        return
    from ..core.sizing.writers import write_chart_row, write_freesewing, write_vit

    found = {key: float(values[key]) for key in ALL_MEASUREMENTS if key in values and math.isfinite(values[key])}
    extension = os.path.splitext(path)[1].lower()
    unit = args.write_unit
    with writing(path):
        if extension == ".vit":
            write_vit(path, found, name=name, sex=sex, unit=unit, notes=f"Measured by ElliMann from {args.file}.")
        elif extension == ".json":
            write_freesewing(path, found, name=name)
            unit = "mm"
        else:
            write_chart_row(path, name, found, unit=unit)
    output.say(f"{PROG} measure: wrote {path}: {len(found)} measurements as {FORMATS[extension]} ({unit})")


def sex_of(mannequin):
    """A mannequin's sex as its reference set's name says it (male, female), or None."""
    name = str(getattr(mannequin, "reference_set", "") or "")
    return "male" if name.startswith("male") else "female" if name.startswith("female") else None
