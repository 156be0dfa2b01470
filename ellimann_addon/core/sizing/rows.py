"""What a measurement file gives, per person or size: the values used, those recognised but not used, those not
recognised, those predicted, and each row checked (units, plausibility, the reference sets' ranges).

A row that fails holds its one-line ``error`` (naming the file, the row and the measurement, and the fix) and no
values; the other rows of a run go on (``MeasurementFile.failed`` lists the ones that failed).
"""

import math
from dataclasses import dataclass, field

from ..errors import ElliMannError
from ..measurements import ABSURD_LIMITS, EXTRA_ABSURD_LIMITS, EXTRA_MEASUREMENTS, MEASUREMENTS
from ..synthesis.extra_refine import extra_request_problems
from ..synthesis.manifest import read_manifest
from ..synthesis.request import checked_request
from ..synthesis.shipped import SHIPPED_SETS
from .names import KEYS
from .predict import PredictionError, conditional_mean, statistics_for

UNITS = {"cm": 1.0, "mm": 0.1, "inch": 2.54}  # cm per unit: the units the formats define
PREDICTOR_LIMITS = {"neck_base": (15.0, 90.0), "biacromial": (10.0, 80.0)}  # cm, as ABSURD_LIMITS for the others
LIMITS = {**ABSURD_LIMITS, **EXTRA_ABSURD_LIMITS, **PREDICTOR_LIMITS}
# Where an adult's values lie (cm; wider than any survey's 1st-99th percentiles, narrower than LIMITS): a value
# outside, that another unit brings inside, was written in that unit (the file's unit is wrong, or the value).
ADULT_CM = {
    "He": (120.0, 230.0),
    "Sh": (25.0, 80.0),
    "Br": (60.0, 200.0),
    "Wa": (45.0, 200.0),
    "Hi": (60.0, 200.0),
    "neck": (20.0, 60.0),
    "upper_arm": (15.0, 60.0),
    "thigh": (30.0, 110.0),
    "calf": (20.0, 70.0),
    "crotch_height": (50.0, 110.0),
    "arm_length": (40.0, 95.0),
    "neck_base": (25.0, 70.0),
    "biacromial": (25.0, 55.0),
}


class SizingError(ElliMannError):
    """A measurement file (or one row of it) that cannot be used: one line naming the file, row and measurement,
    and the fix."""


@dataclass
class SizeRow:
    """One person or size of a file: ``values`` {key: cm} of ElliMann's eleven (given and predicted),
    ``given`` {key: (the file's name, value, its unit)}, ``predictors`` {survey key: cm} used only for a
    prediction, ``predicted`` {key: (cm, sd cm)}, ``unused`` {name: why} (recognised, not used), ``unknown``
    (names not recognised), ``warnings``, and ``error`` (one line) when the row failed."""

    label: str
    values: dict = field(default_factory=dict)
    given: dict = field(default_factory=dict)
    predictors: dict = field(default_factory=dict)
    predicted: dict = field(default_factory=dict)
    unused: dict = field(default_factory=dict)
    unknown: tuple = ()
    warnings: list = field(default_factory=list)
    error: str = None

    @property
    def ok(self):
        return self.error is None

    def request(self):
        """The five {He, Sh, Br, Wa, Hi} (cm) to synthesize."""
        return {key: self.values[key] for key in MEASUREMENTS}

    def extra(self):
        """The extra measurements given {key: cm} (never predicted ones: exact mode meets only what was asked)."""
        return {key: self.values[key] for key in EXTRA_MEASUREMENTS if key in self.values}


@dataclass
class MeasurementFile:
    """A read file: its ``path``, ``format`` (vit, vst, freesewing, chart), ``unit`` (a chart's columns may
    differ: ``units`` {key: unit}), ``sex`` (female, male or None: not said), the ``rows`` (one per person or size,
    in the file's order), and ``notes`` (what was assumed, in words)."""

    path: str
    format: str
    unit: str
    sex: str
    rows: list
    notes: list = field(default_factory=list)
    units: dict = field(default_factory=dict)

    @property
    def failed(self):
        return [row for row in self.rows if not row.ok]

    def unit_of(self, key):
        """The unit the file gives ``key`` in (its own unit for a key it does not give)."""
        return self.units.get(key, self.unit)

    def in_file_unit(self, key, cm):
        """A value of ``key`` in cm, in the unit the file gives it in (for a report in the file's own unit)."""
        return cm / UNITS[self.unit_of(key)]


def set_ranges(sex=None, sets=None):
    """{set name: ranges_cm} of the reference sets a row may be synthesized on: ``sets`` (shipped names or
    folders) when given, else the shipped sets of ``sex`` (every shipped set when None)."""
    if sets is None:
        sets = [name for name in SHIPPED_SETS if sex is None or _sex_of(name) == sex]
    return {str(name): read_manifest(SHIPPED_SETS.get(name, name)).ranges_cm for name in sets}


def _sex_of(name):
    return "male" if str(name).startswith("male") else "female" if str(name).startswith("female") else None


def outside_every_set(request, ranges_by_set):
    """None when ``request`` (the five, cm) lies inside the ranges of some set; else a line saying how far it is
    from the nearest set's ranges (its farthest measurement, cm)."""
    best = None
    for name, ranges in ranges_by_set.items():
        worst = (0.0, None)
        for key in MEASUREMENTS:
            lo, hi = ranges[key]
            by = max(lo - request[key], request[key] - hi, 0.0)
            if by > worst[0]:
                worst = (by, key)
        if worst[1] is None:
            return None
        if best is None or worst[0] < best[0]:
            lo, hi = ranges[worst[1]]
            best = (worst[0], name, worst[1], lo, hi)
    if best is None:
        return None
    by, name, key, lo, hi = best
    return (
        f"{key} {request[key]:.4g} cm is outside every reference set's range; the nearest, {name!r}, takes "
        f"{key} {lo:g}-{hi:g} cm ({by:.2f} cm away)"
    )


def unit_hint(key, value, unit):
    """'' when ``value`` (in ``unit``) is an adult's ``key`` or no other unit makes it one; else a line saying
    which unit does."""
    low, high = ADULT_CM[key]
    if low <= value * UNITS[unit] <= high:
        return ""
    fits = [other for other, scale in UNITS.items() if other != unit and low <= value * scale <= high]
    if not fits:
        return ""
    other = fits[0]
    return f"as {other} it would be {value * UNITS[other]:.4g} cm: is the file's unit {other}, not {unit}?"


def classify(entries, lookup):
    """(given {key: (name, value, unit)}, predictors {key: (name, value, unit)}, unused {name: why}, unknown
    [names]) from ``entries`` [(name, value, unit)] and ``lookup(name) -> (Mapping or None, known)``."""
    given, predictors, unused, unknown = {}, {}, {}, []
    for name, value, unit in entries:
        mapping, known = lookup(name)
        if mapping is None:
            if known:
                unused[name] = "no ElliMann measurement is taken there"
            else:
                unknown.append(name)
        elif mapping.key is None:
            unused[name] = mapping.why
        else:
            target = given if mapping.key in KEYS else predictors
            if mapping.key in target:
                unused[name] = f"the same measurement as {target[mapping.key][0]!r}, which came first"
            else:
                target[mapping.key] = (name, value, unit)
    return given, predictors, unused, unknown


def build_row(label, entries, lookup, where, sex=None, statistics=None, ranges_by_set=None, extrapolate=False):
    """A SizeRow from ``entries`` [(name, value, unit)]: classified, converted to cm, checked, the missing
    ones of the five predicted. ``where`` names the file and row in messages ("sizes.csv row 'M'");
    ``ranges_by_set`` {set: ranges_cm} (default: the shipped sets of ``sex``) for the range check, which
    ``extrapolate`` turns into a warning. A failure is the row's ``error``, never an exception."""
    given, predictors, unused, unknown = classify(entries, lookup)
    row = SizeRow(label, unused=unused, unknown=tuple(unknown))
    try:
        _fill(row, given, predictors, where, sex, statistics, ranges_by_set, extrapolate)
    except SizingError as error:
        row.values, row.predictors, row.predicted, row.error = {}, {}, {}, str(error)
    return row


def _fill(row, given, predictors, where, sex, statistics, ranges_by_set, extrapolate):
    for source, out in ((given, row.values), (predictors, row.predictors)):
        for key, (name, value, unit) in source.items():
            if not (isinstance(value, float) and math.isfinite(value)) or value <= 0:
                raise SizingError(f"{where}: {name} = {value!r} is not a positive number; give it in {unit}")
            cm = value * UNITS[unit]
            hint = unit_hint(key, value, unit)
            if hint:
                low, high = ADULT_CM[key]
                raise SizingError(
                    f"{where}: {name} = {value:g} {unit} is {cm:.4g} cm, not an adult's {key} ({low:g}-{high:g} cm); "
                    + hint
                )
            low, high = LIMITS[key]
            if not low <= cm <= high:
                raise SizingError(
                    f"{where}: {name} = {value:g} {unit} is {cm:.4g} cm, not a plausible {key} ({low:g}-{high:g} cm)"
                )
            out[key] = cm
    row.given = dict(given)
    missing = [key for key in MEASUREMENTS if key not in row.values]
    if missing:
        try:
            population = statistics_for(sex, statistics)
            means, spreads = conditional_mean(population, {**row.values, **row.predictors}, missing)
        except PredictionError as error:
            raise SizingError(f"{where}: {', '.join(missing)} missing and not predicted: {error}") from None
        for key in missing:
            row.values[key] = means[key]
            row.predicted[key] = (means[key], spreads[key])
    try:
        _, warnings = checked_request(row.request())
    except ElliMannError as error:
        what = "predicted " if any(str(error).startswith(key) for key in row.predicted) else ""
        raise SizingError(f"{where}: {what}{error}") from None
    row.warnings.extend(warnings)
    problems = extra_request_problems(row.request(), row.extra())
    if problems:
        raise SizingError(f"{where}: {problems[0]}")
    if ranges_by_set is None:
        ranges_by_set = set_ranges(sex)
    outside = outside_every_set(row.request(), ranges_by_set)
    if outside:
        if not extrapolate:
            raise SizingError(
                f"{where}: {outside}; choose a set whose range holds it, or allow extrapolation (exact mode "
                "reaches some way beyond a set's range)"
            )
        row.warnings.append(outside)
