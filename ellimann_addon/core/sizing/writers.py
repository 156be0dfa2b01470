"""A body's measurements written back for the pattern tools: a Seamly2D / Valentina individual file (.vit), a
FreeSewing measurements set (.json), a size chart's row (.csv). Each measurement goes under the format's own name
where the format has one that is the same measurement (core.sizing.names, the same tables the readers use); the
others go where the format keeps what it has no name for: Seamly2D's custom measurements (``@ellimann_Sh``), the
set's ``ellimann`` section; a chart takes ElliMann's keys. Read back with core.sizing.readers, every value
returns as written (tests/core/sizing/test_writers.py). Files are written atomically.
"""

import csv
import io
import json
import math
import pathlib
from xml.sax.saxutils import quoteattr

from ..files import atomic_write_text
from ..measurements import MEASUREMENT_LABELS
from .names import CHART_LABELS, ELLIMANN_CUSTOM, FREESEWING, FREESEWING_ELLIMANN, KEYS, SEAMLY
from .rows import UNITS, SizingError

DIGITS = 4  # decimals of a written value in its unit (0.1 um in cm): a round trip is exact to that
LABELS = {**MEASUREMENT_LABELS, **MEASUREMENT_LABELS}


def _name_for(table, key):
    return next((row.name for row in table.values() if row.key == key), None)


def _checked(measurements):
    """{key: cm} of ElliMann's measurements in ``measurements`` (others refused), each a positive number."""
    found = {}
    for key, value in measurements.items():
        if key not in KEYS:
            raise SizingError(f"{key!r} is not one of ElliMann's measurements ({', '.join(KEYS)})")
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) or value <= 0:
            raise SizingError(f"{key} is {value!r}; a measurement to write is a positive number of cm")
        found[key] = float(value)
    if not found:
        raise SizingError("no measurements to write")
    return found


def _number(value):
    return f"{value:.{DIGITS}f}".rstrip("0").rstrip(".")


def vit_text(measurements, name="", sex=None, unit="cm", notes=""):
    """The text of an individual measurement file (format 0.3.4) of ``measurements`` {key: cm}."""
    measurements = _checked(measurements)
    if unit not in UNITS:
        raise SizingError(f"unit {unit!r}: a .vit holds {', '.join(UNITS)}")
    given, _, family = name.partition(" ")
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        "<smis>",
        "    <!--Measurements written by ElliMann.-->",
        "    <version>0.3.4</version>",
        "    <read-only>false</read-only>",
        f"    <notes>{_escape(notes)}</notes>",
        f"    <unit>{unit}</unit>",
        "    <pm_system>998</pm_system>",
        "    <personal>",
        f"        <family-name>{_escape(family)}</family-name>",
        f"        <given-name>{_escape(given)}</given-name>",
        "        <birth-date>1800-01-01</birth-date>",
        f"        <gender>{sex if sex in ('female', 'male') else 'unknown'}</gender>",
        "        <email/>",
        "    </personal>",
        "    <body-measurements>",
    ]
    for key, cm in measurements.items():
        own = _name_for(SEAMLY, key)
        value = _number(cm / UNITS[unit])
        if own:
            lines.append(f"        <m name={quoteattr(own)} value={quoteattr(value)}/>")
        else:
            full = quoteattr(f"ElliMann: {LABELS[key]}")
            about = quoteattr(f"ElliMann's {key} (docs/measurements.md), which the known table has no name for")
            lines.append(
                f"        <m name={quoteattr(ELLIMANN_CUSTOM + key)} value={quoteattr(value)} full_name={full} "
                f"description={about}/>"
            )
    lines += ["    </body-measurements>", "</smis>", ""]
    return "\n".join(lines)


def _escape(text):
    return quoteattr(str(text))[1:-1]


def freesewing_data(measurements, name="ElliMann body"):
    """A FreeSewing measurements set (as its public export: values in mm) of ``measurements`` {key: cm}, with the
    ones FreeSewing has no name for in its ``ellimann`` section (cm)."""
    measurements = _checked(measurements)
    theirs, ours = {}, {"units": "cm"}
    for key, cm in measurements.items():
        own = _name_for(FREESEWING, key)
        if own:
            theirs[own] = round(cm * 10.0, DIGITS - 1)
        else:
            ours[key] = round(cm, DIGITS)
    data = {
        "author": "ElliMann",
        "type": "measurementsSet",
        "about": "Contains measurements in mm as well as metadata",
        "name": name,
        "units": "metric",
        "measurements": theirs,
    }
    if len(ours) > 1:
        data[FREESEWING_ELLIMANN] = ours
    return data


def chart_text(rows, unit="cm"):
    """A size chart's text: a header (size, then ElliMann's keys), a unit row, one row per (label, {key: cm}) of
    ``rows``."""
    if unit not in UNITS:
        raise SizingError(f"unit {unit!r}: a chart holds {', '.join(UNITS)}")
    rows = [(str(label), _checked(values)) for label, values in rows]
    keys = [key for key in KEYS if any(key in values for _, values in rows)]
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow([CHART_LABELS[0], *keys])
    writer.writerow(["unit", *([unit] * len(keys))])
    for label, values in rows:
        writer.writerow([label, *(_number(values[k] / UNITS[unit]) if k in values else "" for k in keys)])
    return out.getvalue()


def write_vit(path, measurements, name="", sex=None, unit="cm", notes=""):
    """``measurements`` {key: cm} as a .vit at ``path`` (written atomically)."""
    atomic_write_text(pathlib.Path(path), vit_text(measurements, name, sex, unit, notes))


def write_freesewing(path, measurements, name="ElliMann body"):
    """``measurements`` {key: cm} as a FreeSewing set (.json) at ``path``."""
    atomic_write_text(pathlib.Path(path), json.dumps(freesewing_data(measurements, name), indent=2) + "\n")


def write_chart_row(path, label, measurements, unit="cm"):
    """``measurements`` {key: cm} as a one-row size chart (.csv) at ``path``, labelled ``label``."""
    atomic_write_text(pathlib.Path(path), chart_text([(label, measurements)], unit))
