"""The report CSV of ``batch`` and ``demo``: its columns (requested, measured and error of each of the five and of
the extra measurements a row asked for; with ``--skin``, how its skin was made and what the skin measures beside),
one row per mannequin (cells safe for spreadsheets and terminals), and the batch's report written row by row as a
batch streams."""

import contextlib
import csv
import errno
import io
import os

from ..core.measurements import ALL_MEASUREMENTS, MEASUREMENTS
from ..core.synthesis.request import relative_error
from .output import printable
from .writing import writing

REPORT_COLUMNS = (
    ["line", "name", "status", "message"]
    + list(ALL_MEASUREMENTS)
    + [f"{k}_measured" for k in ALL_MEASUREMENTS]
    + [f"{k}_error_pct" for k in ALL_MEASUREMENTS]
    + ["files", "references"]
    + ["skin_voxel_mm", "skin_blend"]
    + [f"{k}_skin" for k in ALL_MEASUREMENTS]
    + [f"{k}_skin_error_pct" for k in ALL_MEASUREMENTS]
    + ["skin_kind"]  # appended last (issue 42): a reader of the older columns finds them where they were
)

# the result columns, empty until a row has them
EMPTY_RESULTS = {
    column: ""
    for column in REPORT_COLUMNS[REPORT_COLUMNS.index("He_measured") :]
    if column not in ("files", "references")
}


def report_row(
    line,
    name,
    status,
    message,
    requested=None,
    measured=None,
    paths=(),
    references="",
    extra=None,
    skin_settings=None,
    skin_measured=None,
):
    """One report row. ``requested``: the five (cm, MEASUREMENTS order) and ``extra`` the extra measurements asked
    ({key: cm}); ``measured`` ({key: cm}, or the five's 5 values): what the mannequin (its pieces) measures, the
    five and those extra ones; with a skin, ``skin_settings`` (how it was made) and ``skin_measured`` ({key: cm},
    what the skin measures on its mesh). A measurement not asked for has empty cells. Text from the CSV or messages
    is made safe for spreadsheets and terminals (:func:`cell`); ``references``: the reference set the row was
    synthesized from (its name)."""
    row = {
        "line": line,
        "name": cell(name),
        "status": status,
        "message": cell(message or ""),
        "files": cell(" ".join(paths)),
        "references": cell(references),
    }
    asked = dict(zip(MEASUREMENTS, requested)) if requested is not None else {}
    asked.update(extra or {})
    if measured is not None and not isinstance(measured, dict):
        measured = dict(zip(MEASUREMENTS, measured))
    for key in ALL_MEASUREMENTS:
        row[key] = f"{asked[key]:g}" if key in asked else ""
    row.update(EMPTY_RESULTS)
    for suffix, errors, values in (("measured", "error_pct", measured), ("skin", "skin_error_pct", skin_measured)):
        both = [key for key in asked if values is not None and values.get(key) is not None]
        if not both:
            continue
        got = [values[key] for key in both]
        for key, value, error in zip(both, got, relative_error(got, [asked[key] for key in both])):
            row[f"{key}_{suffix}"], row[f"{key}_{errors}"] = f"{value:.4f}", f"{error:.4f}"
    if skin_settings is not None and skin_settings.kind == "body":
        row["skin_kind"] = "body"
    elif skin_settings is not None:
        row["skin_kind"] = "pieces"
        row["skin_voxel_mm"], row["skin_blend"] = f"{skin_settings.voxel_mm:g}", f"{skin_settings.blend:g}"
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


class Report:
    """A batch report written as rows finish, in the CSV's order: each row is appended to REPORT.partial.csv and
    flushed, so a killed run leaves a record of what it did, and nothing of it is held in memory; :meth:`finish`
    makes the partial file REPORT.csv (checked whole, then one atomic rename). Counts the rows by status (and those
    kept)."""

    def __init__(self, path):
        self.path, self.counts = path, {}
        root, extension = os.path.splitext(path)
        self.partial = f"{root}.partial{extension}"
        with writing(self.partial):
            self.stream = open(self.partial, "w", newline="", encoding="utf-8")
        self.writer = csv.DictWriter(self.stream, fieldnames=REPORT_COLUMNS, lineterminator="\n", extrasaction="ignore")
        self._append(self.writer.writeheader)

    def add(self, row):
        for status in (row["status"], "kept" if row.get("kept") else None, "redone" if row.get("redone") else None):
            if status is not None:
                self.counts[status] = self.counts.get(status, 0) + 1
        self._append(lambda: self.writer.writerow(row))

    def _append(self, write):
        with writing(self.partial):
            write()
            self.stream.flush()

    def count(self, *statuses):
        return sum(self.counts.get(status, 0) for status in statuses)

    def finish(self):
        """The partial file, on disk whole (every byte written reached it), renamed REPORT.csv."""
        with writing(self.path):
            self.stream.flush()
            os.fsync(self.stream.fileno())
            written, size = self.stream.buffer.tell(), os.fstat(self.stream.fileno()).st_size
            self.close()
            if size != written:
                raise OSError(errno.EIO, f"the file written is incomplete: {size} of {written} bytes reached the disk")
            os.replace(self.partial, self.path)

    def close(self):
        """Close the partial file, which stays (a run that failed: its record, and --resume picks up)."""
        if self.stream is not None:
            with contextlib.suppress(OSError):
                self.stream.close()
            self.stream = None
