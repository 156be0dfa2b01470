"""Reading the measurement files people have: Seamly2D / Valentina individual files (.vit) and multisize tables
(.vst), FreeSewing measurement sets (.json) and size charts (.csv). Each gives a ``MeasurementFile`` of
``SizeRow`` (core.sizing.rows): one per person or size, the values used, recognised but not used, not recognised,
predicted, and a row's one-line error. The formats: docs/formats/measurement_files.md.

A file that cannot be read at all (not the format, no unit, an unknown chart column, a formula that refers to a
measurement the file does not hold) raises SizingError in one line naming the file and the fix; a row that
fails keeps its error and the others go on. The unit is always the file's: never guessed.
"""

import csv
import difflib
import io
import json
import pathlib
import xml.etree.ElementTree as ElementTree

from .formula import FormulaError, evaluate_all
from .names import CHART, CHART_LABELS, chart_mapping, freesewing_mapping, seamly_mapping
from .rows import UNITS, MeasurementFile, SizeRow, SizingError, build_row, set_ranges

MAX_BYTES = 16 * 1024 * 1024  # a measurement file is kilobytes; a chart of thousands of sizes is still far below
SIZE_STEP_CM = 2.0  # a multisize table's size step, and its height step (the tools' own: the grading's unit)
HEIGHT_STEP_CM = 6.0
SEXES = ("female", "male")
_CHART_UNITS = {"cm": "cm", "mm": "mm", "in": "inch", "inch": "inch", "inches": "inch", '"': "inch"}


def read_measurement_file(path, sex=None, **options):
    """A MeasurementFile from any of the formats, by extension (.vit, .vst, .json, .csv). ``sex`` ('female',
    'male') when the file does not say (a file that says wins unless they differ: then SizingError); ``options``
    go to the reader (``statistics``, ``ranges_by_set``, ``extrapolate``; a .vst's ``sizes`` and ``heights``)."""
    readers = {".vit": read_vit, ".vst": read_vst, ".json": read_freesewing, ".csv": read_chart}
    suffix = pathlib.Path(path).suffix.casefold()
    if suffix not in readers:
        raise SizingError(f"{path}: not a measurement file ElliMann reads (.vit, .vst, .json, .csv)")
    return readers[suffix](path, sex=sex, **options)


def _text(path):
    try:
        data = pathlib.Path(path).read_bytes()
    except OSError as error:
        raise SizingError(f"{path}: cannot be read ({error.strerror or error})") from None
    if len(data) > MAX_BYTES:
        raise SizingError(f"{path}: {len(data):,} bytes is more than a measurement file holds ({MAX_BYTES:,})")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise SizingError(f"{path}: not UTF-8 text; save it as UTF-8") from None


def _xml(path, roots):
    text = _text(path)
    if "<!DOCTYPE" in text or "<!ENTITY" in text:
        raise SizingError(f"{path}: holds a DOCTYPE or ENTITY declaration, which measurement files never do")
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError as error:
        raise SizingError(f"{path}: not well-formed XML ({error})") from None
    if root.tag not in roots:
        raise SizingError(f"{path}: the root element is <{root.tag}>, not <{roots[0]}> (is it the right kind of file?)")
    return root


def _unit(path, root):
    unit = (root.findtext("unit") or "").strip()
    if unit not in UNITS:
        said = f"is {unit!r}" if unit else "is missing"
        raise SizingError(f"{path}: <unit> {said}; it must be one of {', '.join(UNITS)} (ElliMann never guesses one)")
    return unit


def _sex(path, said, asked):
    said = said if said in SEXES else None
    if said and asked and said != asked:
        raise SizingError(f"{path}: the file says {said}, but {asked} was asked; leave it out or change the file")
    return said or asked


def _number(text, path, where):
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise SizingError(f"{path}: {where} is {text!r}, not a number") from None
    return value


def _sex_note(sex):
    return [] if sex else ["the file does not say the person's sex: the female sets and statistics are used"]


def read_vit(path, sex=None, statistics=None, ranges_by_set=None, extrapolate=False):
    """A Seamly2D / Valentina individual measurement file: one person (a row labelled with the person's name)."""
    root = _xml(path, ("smis", "vit"))
    unit = _unit(path, root)
    personal = root.find("personal")
    gender = (personal.findtext("gender") or personal.findtext("sex") or "").strip() if personal is not None else ""
    sex = _sex(path, gender, sex)
    formulas = {}
    for element in root.iter("m"):
        name, value = element.get("name"), element.get("value")
        if not name or value is None:
            raise SizingError(f"{path}: an <m> without a name or a value; every measurement needs both")
        if name in formulas:
            raise SizingError(f"{path}: {name} is given twice; keep one")
        formulas[name] = value
    try:
        values = evaluate_all(formulas)
    except FormulaError as error:
        raise SizingError(f"{path}: {error}") from None
    label = _person(personal) or pathlib.Path(path).stem
    entries = [(name, value, unit) for name, value in values.items()]
    row = build_row(label, entries, seamly_mapping, f"{path}", sex, statistics, ranges_by_set, extrapolate)
    return MeasurementFile(str(path), "vit", unit, sex, [row], _sex_note(sex))


def _person(personal):
    if personal is None:
        return ""
    names = [(personal.findtext(tag) or "").strip() for tag in ("given-name", "family-name")]
    return " ".join(name for name in names if name)


def _steps(element, path, what):
    """(base, [values]) of a .vst's <size> or <height>: min..max by step when given, else the base alone."""
    if element is None or element.get("base") is None:
        raise SizingError(f"{path}: <{what} base=...> is missing; a multisize table needs its base {what}")
    base = _number(element.get("base"), path, f"<{what}> base")
    if element.get("min") is None or element.get("max") is None:
        return base, [base]
    low, high = (_number(element.get(k), path, f"<{what}> {k}") for k in ("min", "max"))
    step = _number(element.get("step", "0"), path, f"<{what}> step")
    if step <= 0 or high < low or (high - low) / step > 1000:
        raise SizingError(f"{path}: <{what}> min {low:g} max {high:g} step {step:g} is not a range of {what}s")
    count = int(round((high - low) / step))
    return base, [low + i * step for i in range(count + 1)]


def _graded(base, increment, current, origin, step, breaks):
    """A multisize value at ``current`` (size or height): linear from ``origin`` by ``increment`` a ``step``, or by
    the grade breaks [(threshold, increment)] step by step from the origin (each step's increment is that of the
    last break at or below the step's start)."""
    if not breaks:
        return base + (current - origin) / step * increment
    steps = int(round(abs(current - origin) / step))
    direction = 1.0 if current > origin else -1.0
    total = 0.0
    for i in range(steps):
        at = origin + direction * i * step
        here = increment
        for threshold, value in sorted(breaks):
            if at >= threshold - 1e-3:
                here = value
        total += direction * here
    return base + total


def _breaks(element, tag, path, name):
    rules = element.find(tag)
    if rules is None:
        return []
    return [
        (_number(b.get("threshold"), path, f"{name} break"), _number(b.get("increment"), path, f"{name} break"))
        for b in rules.iter("break")
    ]


def read_vst(path, sex=None, statistics=None, ranges_by_set=None, extrapolate=False, sizes=None, heights=None):
    """A Seamly2D / Valentina multisize table: one row per (size, height) of its run. The run is the file's sizes
    from min to max by step at its base height (``sizes`` and ``heights``, in the file's unit, choose others; a
    file without a range gives its base size alone). Each value is the measurement's base plus its increments:
    ``size_increase`` per 2 cm of size, ``height_increase`` per 6 cm of height (or the file's grade breaks)."""
    root = _xml(path, ("smms", "vst"))
    unit = _unit(path, root)
    if unit == "inch":
        raise SizingError(f"{path}: a multisize table in inches, which the tools do not grade; save it in cm or mm")
    base_size, run_sizes = _steps(root.find("size"), path, "size")
    base_height, run_heights = _steps(root.find("height"), path, "height")
    run_sizes = [float(s) for s in sizes] if sizes is not None else run_sizes
    run_heights = [float(h) for h in heights] if heights is not None else [base_height]
    aliases = {}
    for element in root.iter("size"):
        if element.get("value") is not None and element.get("alias"):
            aliases[_number(element.get("value"), path, "a size's value")] = element.get("alias")
    table = []
    for element in root.find("body-measurements").iter("m") if root.find("body-measurements") is not None else ():
        name = element.get("name")
        if not name:
            raise SizingError(f"{path}: an <m> without a name")
        numbers = [
            _number(element.get(k, "0"), path, f"{name} {k}") for k in ("base", "size_increase", "height_increase")
        ]
        table.append(
            (name, *numbers, _breaks(element, "sizeRules", path, name), _breaks(element, "heightRules", path, name))
        )
    if not table:
        raise SizingError(f"{path}: no <m> measurements (a table before format 0.4 must be saved again by the tools)")
    scale = UNITS[unit]
    ranges_by_set = ranges_by_set if ranges_by_set is not None else set_ranges(sex)  # read once for the run
    rows = []
    for height in run_heights:
        for size in run_sizes:
            label = aliases.get(size, f"{size:g}") + ("" if heights is None else f"/{height:g}")
            where = f"{path} size {label}"
            entries, negative = [], None
            for name, base, per_size, per_height, size_breaks, height_breaks in table:
                value = _graded(base, per_size, size, base_size, SIZE_STEP_CM / scale, size_breaks)
                value += _graded(0.0, per_height, height, base_height, HEIGHT_STEP_CM / scale, height_breaks)
                if value <= 0 and "angle" not in name and negative is None:
                    negative = (
                        f"{where}: {name} is {value:.4g} {unit} (base {base:g}, {per_size:+g} a size, "
                        f"{per_height:+g} a height): the increments make it negative at this size; "
                        "change the increments or leave the size out"
                    )
                entries.append((name, value, unit))
            row = build_row(label, entries, seamly_mapping, where, sex, statistics, ranges_by_set, extrapolate)
            if negative:
                row.values, row.predicted, row.error = {}, {}, negative
            rows.append(row)
    notes = _sex_note(sex)
    if sizes is None and len(run_sizes) == 1:
        notes.append("the file gives no size range (min, max, step): its base size alone")
    return MeasurementFile(str(path), "vst", unit, sex, rows, notes)


def read_freesewing(path, sex=None, statistics=None, ranges_by_set=None, extrapolate=False):
    """A FreeSewing measurements set (JSON): its ``measurements`` (the public export) or ``measies`` (the
    account's), in mm by the format's definition; ElliMann's own ``ellimann`` section ({"units": "cm", "He": ...})
    carries what FreeSewing has no name for."""
    try:
        data = json.loads(_text(path))
    except ValueError as error:
        raise SizingError(f"{path}: not JSON ({error})") from None
    if not isinstance(data, dict):
        raise SizingError(f"{path}: a FreeSewing set is a JSON object")
    values = data.get("measurements", data.get("measies"))
    if not isinstance(values, dict):
        raise SizingError(
            f"{path}: not a FreeSewing measurements set (no 'measurements' or 'measies' object of values in mm)"
        )
    entries = []
    for name, value in values.items():
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise SizingError(f"{path}: {name} is {value!r}, not a number (mm)")
        entries.append((name, float(value), "mm"))
    ours = data.get("ellimann", {})
    lookup = freesewing_mapping
    if ours:
        if not isinstance(ours, dict) or ours.get("units") not in UNITS:
            raise SizingError(f"{path}: the 'ellimann' section needs \"units\" ({', '.join(UNITS)}) and numbers")
        lookup = _with_ellimann(freesewing_mapping)
        for key, value in ours.items():
            if key != "units":
                if isinstance(value, bool) or not isinstance(value, int | float):
                    raise SizingError(f"{path}: ellimann.{key} is {value!r}, not a number")
                entries.append((f"ellimann.{key}", float(value), ours["units"]))
    sex = _sex(path, data.get("sex"), sex)
    label = str(data.get("name") or pathlib.Path(path).stem)
    row = build_row(label, entries, lookup, f"{path}", sex, statistics, ranges_by_set, extrapolate)
    notes = _sex_note(sex)
    if data.get("units") == "imperial" or data.get("imperial") is True:
        notes.append("the set is shown in inches on FreeSewing, but its values are mm, as every set's")
    return MeasurementFile(str(path), "freesewing", "mm", sex, [row], notes)


def _with_ellimann(lookup):
    def find(name):
        if name.startswith("ellimann."):
            mapping = CHART.get(name[len("ellimann.") :])
            return mapping, mapping is not None
        return lookup(name)

    return find


def _header(cell):
    """(name, unit or None) of a chart's header cell: 'Bust (in)', 'waist [cm]'."""
    text = cell.strip()
    for opening, closing in (("(", ")"), ("[", "]")):
        if text.endswith(closing) and opening in text:
            name, _, unit = text[:-1].rpartition(opening)
            return name.strip(), _chart_unit(unit)
    return text, None


def _chart_unit(text):
    return _CHART_UNITS.get(text.strip().casefold(), False)


def read_chart(path, sex=None, statistics=None, ranges_by_set=None, extrapolate=False):
    """A size chart (CSV): one row per size, a column naming it (size, label or name; else the first), named
    measurement columns (docs/formats/measurement_files.md), the unit in a unit row ("unit, cm, cm, ...") or in
    each header ("bust (in)"). An empty cell is not given (one of the five is then predicted)."""
    rows_text = list(csv.reader(io.StringIO(_text(path))))
    rows_text = [row for row in rows_text if any(cell.strip() for cell in row)]
    if len(rows_text) < 2:
        raise SizingError(f"{path}: a size chart needs a header row and at least one size")
    header = [_header(cell) for cell in rows_text[0]]
    body = rows_text[1:]
    units = [unit for _, unit in header]
    if body and body[0] and body[0][0].strip().casefold().rstrip(":") in ("unit", "units"):
        units = [_chart_unit(cell) if cell.strip() else None for cell in body[0][1:]]
        units = [None] + units + [None] * (len(header) - 1 - len(units))
        body = body[1:]
    names = [name for name, _ in header]
    label_column = next((i for i, n in enumerate(names) if n.casefold() in CHART_LABELS), 0)
    columns = []
    for i, name in enumerate(names):
        if i == label_column:
            continue
        mapping = chart_mapping(name)
        if mapping is None:
            near = difflib.get_close_matches(name.casefold(), [n.casefold() for n in CHART], n=1)
            hint = f" (did you mean {near[0]!r}?)" if near else ""
            raise SizingError(
                f"{path}: column {name!r} is not a measurement ElliMann knows{hint}; rename it to one of the "
                "names in docs/formats/measurement_files.md, or remove the column"
            )
        if mapping.key is None:  # recognised, not used: its unit does not matter
            units[i] = units[i] or "-"
        elif units[i] is False:
            raise SizingError(f"{path}: column {name!r} has a unit ElliMann does not know; use cm, mm or in")
        elif units[i] is None:
            raise SizingError(
                f"{path}: column {name!r} has no unit; add a unit row (unit, cm, cm, ...) or write it "
                f"'{name} (cm)' (ElliMann never guesses one)"
            )
        columns.append(i)
    ranges_by_set = ranges_by_set if ranges_by_set is not None else set_ranges(sex)  # read once for the run
    rows = []
    for cells in body:
        label = cells[label_column].strip() if label_column < len(cells) else ""
        where = f"{path} row {label!r}"
        entries, bad = [], None
        for i in columns:
            cell = cells[i].strip() if i < len(cells) else ""
            if not cell:
                continue
            try:
                entries.append((names[i], float(cell), units[i]))
            except ValueError:
                bad = bad or f"{where}: {names[i]} is {cell!r}, not a number; write it in {units[i]}"
        if bad:
            rows.append(SizeRow(label, error=bad))
            continue
        rows.append(build_row(label, entries, chart_mapping_pair, where, sex, statistics, ranges_by_set, extrapolate))
    used_units = {}
    for i in columns:
        mapping = chart_mapping(names[i])
        if mapping.key:
            used_units[mapping.key] = units[i]
    common = max(set(used_units.values()), key=list(used_units.values()).count) if used_units else "cm"
    return MeasurementFile(str(path), "chart", common, sex, rows, _sex_note(sex), used_units)


def chart_mapping_pair(name):
    """(Mapping or None, known) of a chart column, as the other formats' lookups."""
    mapping = chart_mapping(name)
    return mapping, mapping is not None
