"""The report CSV of ``synth --report`` and ``batch``: its columns, one row per mannequin (cells safe for
spreadsheets and terminals), and what exact mode missed."""

import csv
import io
import math

from ..core.constants import MEASUREMENTS
from ..core.synthesis.refine import EXACT_TOLERANCE
from ..core.synthesis.request import relative_error
from .output import printable


def misses(measured, requested):
    """The requested measurements exact mode missed by more than its tolerance (EXACT_TOLERANCE, the
    criterion it stops at): [(key, m_T cm, requested cm, error %)]."""
    return [
        (key, float(m), float(r), abs(m - r) / r * 100.0)
        for key, m, r in zip(MEASUREMENTS, measured, requested)
        if abs(math.log(max(float(m), 1e-12) / float(r))) > EXACT_TOLERANCE
    ]


def missed_text(missed):
    return (
        "exact mode missed "
        + ", ".join(f"{key} by {error:.2f}% (m_T {m:.2f} cm for {r:g} cm)" for key, m, r, error in missed)
        + f" (tolerance {EXACT_TOLERANCE * 100:g}%; the file is the closest it found)"
    )


REPORT_COLUMNS = (
    ["line", "name", "status", "message"]
    + list(MEASUREMENTS)
    + [f"{k}_measured" for k in MEASUREMENTS]
    + [f"{k}_error_pct" for k in MEASUREMENTS]
    + ["files", "references"]
)


def report_row(line, name, status, message, requested=None, measured=None, paths=(), references=""):
    """One report row; text from the CSV or messages is made safe for spreadsheets and terminals (:func:`cell`).
    ``references``: the reference set the row was synthesized from (its name)."""
    row = {
        "line": line,
        "name": cell(name),
        "status": status,
        "message": cell(message or ""),
        "files": cell(" ".join(paths)),
        "references": cell(references),
    }
    error = relative_error(measured, requested) if measured is not None else None
    for i, key in enumerate(MEASUREMENTS):
        row[key] = f"{requested[i]:g}" if requested is not None else ""
        row[f"{key}_measured"] = f"{measured[i]:.4f}" if measured is not None else ""
        row[f"{key}_error_pct"] = f"{error[i]:.4f}" if error is not None else ""
    return row


def cell(text):
    """A report cell: control characters escaped (:func:`printable`), and text a spreadsheet would take for
    a formula (starting with =, +, - or @) neutralised with a leading apostrophe, as OWASP recommends."""
    text = printable(text)
    return "'" + text if text[:1] in ("=", "+", "-", "@") else text


def report_csv(rows):
    stream = io.StringIO()
    writer = csv.DictWriter(stream, fieldnames=REPORT_COLUMNS, lineterminator="\n", extrasaction="ignore")
    writer.writeheader()
    writer.writerows(rows)
    return stream.getvalue()
