"""Populations: rows of tailor measurements sampled from a survey's summary statistics (mean and covariance,
cm), as a multivariate normal, to feed ``batch``. The file format is documented in docs/population.md; the
shipped surveys are in ``core/populations/`` (``ansur2_female``, with its citation).

The same seed gives the same rows on every machine and numpy major: the normal deviates are numpy's
``Generator(PCG64(seed)).standard_normal`` (a stream numpy keeps stable), the Cholesky factor and the
product with it are computed here in a fixed order (no LAPACK or BLAS whose summation order could differ).
A sampled row outside what a body can be (a measurement outside ``constants.ABSURD_LIMITS``, or any value
<= 0) is refused and counted, never replaced: the accepted rows keep their sample numbers.
"""

import json
import math
import os
import pathlib

import numpy as np

from ..errors import ElliMannError
from ..measurements import ABSURD_LIMITS, MEASUREMENTS

POPULATION_FORMAT = "ellimann-population"
POPULATION_VERSION = 1
POPULATIONS_FOLDER = pathlib.Path(__file__).resolve().parent / "populations"
MAX_SAMPLES = 1_000_000  # more rows than any batch is meant for (a 20,000-row batch takes minutes)
_REQUIRED = ("format", "version", "name", "citation", "units", "keys", "mean", "covariance")
_OPTIONAL = ("about", "n", "source_columns", "std", "correlation", "percentiles", "min", "max")
_CONSISTENT = 0.01  # relative agreement asked of std and correlation with the covariance (files round them)


class PopulationError(ElliMannError):
    """A statistics file that cannot be used: the message names the file and the field."""


class Population:
    """A survey's statistics: ``keys`` (the five measurements first, then any others), ``mean`` (k,) and
    ``covariance`` (k, k) in cm, its ``name`` and ``citation``."""

    def __init__(self, name, citation, keys, mean, covariance, source=""):
        self.name, self.citation, self.keys, self.source = name, citation, tuple(keys), source
        self.mean = np.asarray(mean, dtype=float)
        self.covariance = np.asarray(covariance, dtype=float)
        self.factor = cholesky(self.covariance, self.keys, source)

    def sample(self, count, seed):
        """(rows (count, k) cm, accepted (count,) bool): ``count`` draws from N(mean, covariance) with ``seed``."""
        count = check_count(count)
        if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
            raise PopulationError(f"seed must be a non-negative integer, got {seed!r}")
        deviates = np.random.Generator(np.random.PCG64(int(seed))).standard_normal((count, len(self.keys)))
        rows = np.empty_like(deviates)
        for i in range(len(self.keys)):  # mean + L z, each sum in the order of j (the same bits everywhere)
            total = np.full(count, self.mean[i])
            for j in range(i + 1):
                total += self.factor[i, j] * deviates[:, j]
            rows[:, i] = total
        return rows, plausible(rows, self.keys)


def check_count(count):
    if isinstance(count, bool) or not isinstance(count, int | np.integer) or not 1 <= count <= MAX_SAMPLES:
        raise PopulationError(f"the number of rows must be an integer from 1 to {MAX_SAMPLES:,}, got {count!r}")
    return int(count)


def plausible(rows, keys):
    """(B,) bool: every value > 0 and each of the five measurements within ``ABSURD_LIMITS``."""
    good = np.all(rows > 0.0, axis=1)
    for i, key in enumerate(keys):
        if key in ABSURD_LIMITS:
            low, high = ABSURD_LIMITS[key]
            good &= (rows[:, i] >= low) & (rows[:, i] <= high)
    return good


def cholesky(covariance, keys=(), source=""):
    """Lower-triangular L with L L^T = covariance, computed row by row in a fixed order; PopulationError if the
    covariance is not symmetric positive definite (naming the first measurement where it fails)."""
    c = np.asarray(covariance, dtype=float)
    k = len(c)
    where = f"{source}: " if source else ""
    if c.shape != (k, k) or not np.all(np.isfinite(c)):
        raise PopulationError(f"{where}covariance must be a finite {k} x {k} matrix, got shape {c.shape}")
    if not np.array_equal(c, c.T):
        i, j = np.argwhere(c != c.T)[0]
        row, column = (keys[i], keys[j]) if keys else (i, j)
        raise PopulationError(f"{where}covariance is not symmetric: [{row}][{column}] {c[i, j]:g} vs {c[j, i]:g}")
    factor = np.zeros_like(c)
    for i in range(k):
        for j in range(i + 1):
            total = c[i, j]
            for m in range(j):
                total -= factor[i, m] * factor[j, m]
            if i == j:
                if not total > 1e-12 * max(c[i, i], 1e-300):
                    name = keys[i] if keys else str(i)
                    raise PopulationError(
                        f"{where}covariance is not positive definite (at {name}: a variance that "
                        "the others already explain, or more); a survey's covariance must be"
                    )
                factor[i, i] = math.sqrt(total)
            else:
                factor[i, j] = total / factor[j, j]
    return factor


def shipped_populations():
    """Names of the shipped surveys (``core/populations/NAME.json``)."""
    return sorted(p.stem for p in POPULATIONS_FOLDER.glob("*.json"))


def load_population(name_or_path):
    """A shipped survey by name (``ansur2_female``) or a statistics file by path; PopulationError naming the
    file and the field for anything it cannot use."""
    text = os.fspath(name_or_path)
    path = pathlib.Path(text)
    if not text.endswith(".json") and os.sep not in text and "/" not in text:
        path = POPULATIONS_FOLDER / f"{text}.json"
        if not path.is_file():
            raise PopulationError(
                f"no shipped statistics named {text!r}; shipped: {', '.join(shipped_populations())}"
                " (or give the path of a .json file)"
            )
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise PopulationError(f"{path}: file does not exist") from None
    except (OSError, UnicodeDecodeError, ValueError) as error:
        raise PopulationError(f"{path}: cannot be read as JSON ({error})") from None
    return population_from_dict(data, str(path))


def population_from_dict(data, source="statistics"):
    def fail(field, text):
        return PopulationError(f"{source}: {field} {text}")

    if not isinstance(data, dict):
        raise fail("file", "must hold a JSON object")
    if data.get("format") != POPULATION_FORMAT:
        raise fail("format", f"must be {POPULATION_FORMAT!r}")
    if data.get("version") != POPULATION_VERSION:
        raise fail("version", f"is {data.get('version')!r}; this ElliMann reads version {POPULATION_VERSION}")
    unknown = [key for key in data if key not in _REQUIRED + _OPTIONAL]
    if unknown:
        raise fail(unknown[0], f"is not a field of a statistics file (fields: {', '.join(_REQUIRED + _OPTIONAL)})")
    missing = [key for key in _REQUIRED if key not in data]
    if missing:
        raise fail(missing[0], "is missing")
    if data["units"] != "cm":
        raise fail("units", f"must be 'cm', got {data['units']!r}")
    keys = data["keys"]
    if not isinstance(keys, list) or not all(isinstance(k, str) and k for k in keys) or len(set(keys)) != len(keys):
        raise fail("keys", "must be a list of distinct names")
    if list(keys[: len(MEASUREMENTS)]) != list(MEASUREMENTS):
        raise fail("keys", f"must start with {', '.join(MEASUREMENTS)} (ElliMann's measurements), got {keys[:5]}")
    mean = _per_key(data, "mean", keys, fail)
    low = [(k, v) for k, v in zip(keys, mean) if v <= 0]
    if low:
        raise fail(f"mean.{low[0][0]}", f"must be > 0 cm, got {low[0][1]:g}")
    covariance = data["covariance"]
    if (
        not isinstance(covariance, list)
        or len(covariance) != len(keys)
        or not all(isinstance(row, list) and len(row) == len(keys) for row in covariance)
        or not all(_finite(v) for row in covariance for v in row)
    ):
        raise fail("covariance", f"must be a {len(keys)} x {len(keys)} matrix of numbers (cm^2), in the order of keys")
    covariance = np.array(covariance, dtype=float)
    negative = [k for k, v in zip(keys, np.diag(covariance)) if v <= 0]
    if negative:
        raise fail(f"covariance[{negative[0]}][{negative[0]}]", "must be > 0 (a variance)")
    if "std" in data:
        std = _per_key(data, "std", keys, fail)
        for key, s, v in zip(keys, std, np.diag(covariance)):
            if s <= 0 or abs(s - math.sqrt(v)) > _CONSISTENT * math.sqrt(v):
                raise fail(f"std.{key}", f"is {s:g}, but the covariance gives {math.sqrt(v):.4g}")
    if "correlation" in data:
        scale = np.sqrt(np.diag(covariance))
        expected = covariance / np.outer(scale, scale)
        given = np.array(data["correlation"], dtype=float) if _matrix(data["correlation"], len(keys)) else None
        if given is None or np.abs(given - expected).max() > _CONSISTENT:
            raise fail("correlation", "does not agree with the covariance (or is not a matrix in the order of keys)")
    for field in ("name", "citation"):
        if not isinstance(data[field], str) or not data[field].strip():
            raise fail(field, "must be a non-empty text")
    return Population(data["name"], data["citation"], keys, mean, covariance, source)


def _finite(value):
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _matrix(value, size):
    return (
        isinstance(value, list)
        and len(value) == size
        and all(isinstance(row, list) and len(row) == size and all(map(_finite, row)) for row in value)
    )


def _per_key(data, field, keys, fail):
    values = data[field]
    if not isinstance(values, dict):
        raise fail(field, "must map each key to a number (cm)")
    unknown = [k for k in values if k not in keys]
    if unknown:
        raise fail(f"{field}.{unknown[0]}", "is not one of keys")
    missing = [k for k in keys if k not in values]
    if missing:
        raise fail(f"{field}.{missing[0]}", "is missing")
    bad = [k for k in keys if not _finite(values[k])]
    if bad:
        raise fail(f"{field}.{bad[0]}", f"must be a finite number, got {values[bad[0]]!r}")
    return [float(values[k]) for k in keys]
