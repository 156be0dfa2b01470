"""The measurements CSV ``batch`` reads, as a stream: its header and row count first (so a file that cannot be
read is refused before anything is written), then its rows one at a time, each checked where it enters (the
five, the extra measurements, the reference set, the name) and named, a name an earlier row holds refused. Only
the names seen are kept (for the duplicates), so memory stays flat in the row count."""

import csv
import difflib
from typing import NamedTuple

from ..core.errors import MeasurementError, ReferenceSetError
from ..core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ..core.synthesis.extra_refine import extra_request_problems
from ..core.synthesis.request import validate_request
from . import output
from .output import UsageError

COLUMNS = MEASUREMENTS + EXTRA_MEASUREMENTS + ("name", "references")
TYPO_CUTOFF = 0.8  # difflib's ratio: an unknown column this close to a known one is taken for a misspelling of it
SHOWN_LINES = 5  # rows with more cells than the header named in the warning (the rest counted)


class Row(NamedTuple):
    """One row of the CSV: ``values`` the five (cm) or None when ``error`` says why the row is refused."""

    line: int  # in the file, the header being line 1
    name: str
    values: list
    error: str
    warnings: list  # the five outside the reference range (allowed)
    reference: object  # the ReferenceSet of its ``references`` cell (None if that is the error)
    extra: dict  # the extra measurements it asks for {key: cm}


class MeasurementsCsv:
    """A measurements CSV: ``columns`` {canonical name: index} from its header, ``count`` its rows that are not
    blank, ``references`` the distinct ``references`` cells of the rows of shard ``shard`` of ``shards``; what is
    not read, for a warning before any row is made: ``unknown`` (the header's titles that name no column: a
    misspelling of one is refused, UsageError) and ``overfull`` (the lines of rows with more cells than the header,
    each refused as its row's error; ``overfull_count`` of them)."""

    def __init__(self, path, shard=1, shards=1):
        self.path = path
        try:
            with open(path, newline="", encoding="utf-8-sig") as stream:
                reader = csv.reader(stream)
                header = next(reader, None)
                self.columns = self._columns(header)
                self.width = len(header)
                self.count, self.references = 0, set()
                self.overfull, self.overfull_count = [], 0
                where = self.columns.get("references")
                for line, record in enumerate(reader, start=2):
                    if not any(cell.strip() for cell in record):
                        continue
                    filled = [index for index in self.untitled if index < len(record) and record[index].strip()]
                    self.unknown += [f"(column {index + 1}, no title)" for index in filled]
                    self.untitled = [index for index in self.untitled if index not in filled]
                    if self._spilled(record):
                        self.overfull_count += 1
                        if len(self.overfull) < SHOWN_LINES:
                            self.overfull.append(line)
                    if self.count % shards == shard - 1 and where is not None and where < len(record):
                        self.references.add(record[where].strip())
                    self.count += 1
        except UnicodeDecodeError:
            raise UsageError(f"{path} is not a UTF-8 text CSV") from None

    def _columns(self, header):
        if not header:
            raise UsageError(f"{self.path} is empty; expected a header row He,Sh,Br,Wa,Hi[,name]")
        columns, self.unknown, self.untitled = {}, [], []
        for index, title in enumerate(header):
            key = title.strip().lower()
            canonical = next((c for c in COLUMNS if c.lower() == key), None)
            if canonical in columns:
                raise UsageError(f"{self.path}: column {canonical} appears twice in the header")
            if canonical:
                columns[canonical] = index
            elif key:
                self.unknown.append(title.strip())
            else:  # named in the warning only if a row fills it (a spreadsheet's trailing comma is no column)
                self.untitled.append(index)
        for title in self.unknown:
            near = difflib.get_close_matches(title.lower(), [c.lower() for c in COLUMNS], n=1, cutoff=TYPO_CUTOFF)
            if near:
                meant = next(c for c in COLUMNS if c.lower() == near[0])
                taken = " (it is there too)" if meant in columns else ""
                raise UsageError(
                    f"{self.path}: column {title!r} is not one batch reads: did you mean {meant}{taken}? The columns "
                    f"are {known_columns()}"
                )
        missing = [m for m in MEASUREMENTS if m not in columns]
        if missing:
            raise UsageError(
                f"{self.path}: header lacks column(s) {', '.join(missing)}; expected He,Sh,Br,Wa,Hi[,name]"
            )
        return columns

    def _spilled(self, record):
        """Whether a row has cells (not blank) beyond the header's columns: a comma inside a name, a shifted row."""
        return any(cell.strip() for cell in record[self.width :])

    def warnings(self):
        """The lines that say, before any row is made, what of the file is not read."""
        out = []
        if self.unknown:
            out.append(
                f"{self.path}: column(s) {', '.join(self.unknown)} are not read (the columns are {known_columns()})"
            )
        if self.overfull_count:
            lines = ", ".join(map(str, self.overfull)) + (" …" if self.overfull_count > len(self.overfull) else "")
            out.append(
                f"{self.path}: {self.overfull_count} row(s) have more cells than the header's {self.width} (line "
                f"{lines}): refused (a comma inside a cell needs quotes)"
            )
        return out

    def rows(self, reference_of, name_pattern):
        """Every row that is not blank, in order, checked and named (:class:`Row`). ``reference_of(text)``: the
        ReferenceSet of a ``references`` cell ("" for the command's own), whose ranges and limits the row is
        checked against; a cell naming no usable set is that row's error. ``name_pattern``: what a name may be."""
        names = Names()
        with open(self.path, newline="", encoding="utf-8-sig") as stream:
            reader = csv.reader(stream)
            next(reader, None)
            for line, record in enumerate(reader, start=2):
                if any(cell.strip() for cell in record):
                    yield names.named(self._row(line, record, reference_of, name_pattern))

    def _cell(self, record, key):
        index = self.columns.get(key)
        return record[index].strip() if index is not None and index < len(record) else ""

    def _row(self, line, record, reference_of, name_pattern):
        name, reference = self._cell(record, "name"), None
        try:
            if self._spilled(record):
                cells = len(record) - next(i for i, cell in enumerate(reversed(record)) if cell.strip())
                raise MeasurementError(
                    "row", f"has {cells} cells, the header {self.width} (a comma inside a cell needs quotes)"
                )
            try:
                reference = reference_of(self._cell(record, "references"))
            except ReferenceSetError as error:
                raise MeasurementError("references", output.one_line(error)) from None
            values = [self._number(record, key, required=True) for key in MEASUREMENTS]
            warnings = validate_request(values, reference.ranges, reference.absurd_limits)
            extra = {key: self._number(record, key) for key in EXTRA_MEASUREMENTS if self._cell(record, key)}
            problems = extra_request_problems(dict(zip(MEASUREMENTS, values)), extra)
            if problems:
                raise MeasurementError(problems[0].split(" ")[0], problems[0].split(" ", 1)[1])
            if name and not name_pattern.match(name):
                raise MeasurementError("name", f"{name!r} must be letters, digits, '.', '_' or '-' (a file name)")
            return Row(line, name, values, None, warnings, reference, extra)
        except MeasurementError as error:
            return Row(line, name, None, str(error), [], reference, {})

    def _number(self, record, key, required=False):
        """A measurement's cell in cm (an empty one: MeasurementError if ``required``)."""
        cell = self._cell(record, key)
        if not cell and required:
            raise MeasurementError(key, "is empty")
        try:
            return float(cell)
        except ValueError:
            raise MeasurementError(key, f"{cell!r} is not a number (cm)") from None


class Names:
    """Every row's output name (``row-NNNNN`` from its line when the CSV gives none), a row whose name an earlier
    good row holds refused (letter case ignored: the files would clash on macOS and Windows). Runs over every row
    of the CSV, whatever the shard, so every shard refuses the same rows. Holds the names seen (case-folded, with
    the first line and, where it differs, the first spelling)."""

    def __init__(self):
        self.lines, self.spelled = {}, {}

    def named(self, row):
        name = row.name or f"row-{row.line - 1:05d}"
        key = name.casefold()
        error = row.error
        if error is None and key in self.lines:
            first = self.spelled.get(key, key)
            same = "" if first == name else f" (as {first!r}; file names ignore case on some systems)"
            error = f"name: {name!r} is already used on line {self.lines[key]}{same}"
        elif error is None:
            self.lines[key] = row.line
            if name != key:
                self.spelled[key] = name
        return row._replace(name=name, error=error)


def known_columns():
    """The columns batch reads, as the help says them."""
    return f"{','.join(MEASUREMENTS)} (cm), optional {', '.join(EXTRA_MEASUREMENTS)} (cm), name and references"
