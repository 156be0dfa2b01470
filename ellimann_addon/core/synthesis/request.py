"""A synthesis request: five tailor measurements in cm (He, Sh, Br, Wa, Hi), checked; its name; the error of m_T
against it (the one formula every report, panel and table uses)."""

import math

import numpy as np

from ..constants import RANGES
from ..errors import MeasurementError
from ..measurements import ABSURD_LIMITS, MEASUREMENTS
from .options import is_number


def validate_request(me, ranges=None, limits=None):
    """Check a request {He, Sh, Br, Wa, Hi} in cm (a dict, or a sequence in that order); the warnings of
    :func:`checked_request`."""
    return checked_request(me, ranges, limits)[1]


def checked_request(me, ranges=None, limits=None):
    """A request {He, Sh, Br, Wa, Hi} in cm (a dict, or a sequence in that order), checked: ((5,) float array,
    warnings).

    Raises MeasurementError naming the field for a missing key, a non-number, NaN/inf, a value
    <= 0 or outside ``limits``. The warnings are for values outside the reference range L
    (``ranges``; allowed: exact mode reaches them, IDW cannot leave the RMs' hull). ``ranges`` and ``limits``
    are the reference set's (``ReferenceSet.ranges``, ``.absurd_limits``); by default the female set's
    RANGES and ABSURD_LIMITS.
    """
    values = request_values(me)
    ranges, limits = ranges or RANGES, limits or ABSURD_LIMITS
    warnings = []
    for key, value in zip(MEASUREMENTS, values):
        low, high = limits[key]
        if not (is_number(value) and value > 0 and low <= value <= high):  # NaN fails too; the message says which
            accepted = f"accepted range {low:g}-{high:g} cm"
            if not is_number(value):
                raise MeasurementError(key, f"must be a number in cm, got {value!r} ({accepted})")
            if not math.isfinite(value):
                raise MeasurementError(key, f"must be a finite number, got {value!r} ({accepted})")
            if value <= 0:
                raise MeasurementError(key, f"must be > 0, got {value:g} ({accepted})")
            raise MeasurementError(key, f"{value:g} cm is not a plausible value ({accepted})")
        lo, hi = ranges[key]
        if value < lo or value > hi:
            bound = lo if value < lo else hi
            by = abs(value - bound)
            warnings.append(
                f"{key} = {value:g} cm is outside the reference range {lo:g}-{hi:g} cm by {by:.4g} cm "
                f"({100.0 * by / bound:.1f}%): the paper's IDW stays inside the range, proportional "
                "IDW and exact mode extrapolate"
            )
    return np.array(values, dtype=float), warnings


def request_values(me):
    """The five values of a request (dict or sequence), in the order of MEASUREMENTS, unchecked; MeasurementError
    for a missing or unknown key or a wrong count."""
    if isinstance(me, dict):
        missing = [key for key in MEASUREMENTS if key not in me]
        if missing:
            raise MeasurementError(missing[0], f"is missing; a request needs {', '.join(MEASUREMENTS)} in cm")
        unknown = [key for key in me if key not in MEASUREMENTS]
        if unknown:
            raise MeasurementError(str(unknown[0]), f"is not a measurement; expected {', '.join(MEASUREMENTS)}")
        return [me[key] for key in MEASUREMENTS]
    if isinstance(me, str):
        raise MeasurementError("request", "must be a dict or 5 numbers He, Sh, Br, Wa, Hi (cm)")
    try:
        values = list(me)
    except TypeError:
        raise MeasurementError("request", "must be a dict or 5 numbers He, Sh, Br, Wa, Hi (cm)") from None
    if len(values) != len(MEASUREMENTS):
        field = MEASUREMENTS[len(values)] if len(values) < len(MEASUREMENTS) else "request"
        raise MeasurementError(field, f"a request needs 5 values He, Sh, Br, Wa, Hi (cm), got {len(values)}")
    return values


def request_array(me, ranges=None, limits=None):
    """Validated request as a (5,) float array (warnings dropped; :func:`checked_request` gives both)."""
    return checked_request(me, ranges, limits)[0]


def mannequin_name(me):
    """'ElliMann 159-43-117-104-117': the name of a synthesized mannequin, from its request (checked where it
    entered)."""
    return "ElliMann " + "-".join(f"{float(v):.6g}" for v in request_values(me))


def relative_error(measured, requested, signed=False):
    """Relative error of m_T against the request, in %: 100 |measured - requested| / requested.

    Arrays (..., 5) in the order of MEASUREMENTS, or dicts keyed by them (then a (5,) array).
    ``signed``: 100 (measured - requested) / requested instead (positive when m_T is larger).
    The one formula every report, panel and table uses.
    """
    measured, requested = (
        np.asarray([v[k] for k in MEASUREMENTS] if isinstance(v, dict) else v, dtype=float)
        for v in (measured, requested)
    )
    error = 100.0 * (measured - requested) / requested
    return error if signed else np.abs(error)


def validate_requests(requests, ranges=None, limits=None):
    """(B, 5) array check for batches (against ``limits``, as :func:`validate_request`); raises MeasurementError
    naming the row and field."""
    try:
        requests = np.atleast_2d(np.asarray(requests, dtype=float))
    except (TypeError, ValueError):
        raise MeasurementError("requests", "must be numbers (cm) in rows of He, Sh, Br, Wa, Hi") from None
    if requests.ndim != 2 or requests.shape[1] != len(MEASUREMENTS):
        raise MeasurementError("requests", f"must have shape (B, 5) (He, Sh, Br, Wa, Hi), got {requests.shape}")
    # One vectorised test of what validate_request refuses (every value is a float here); the message is that of
    # validate_request on the first bad row, as checking row by row would give.
    limits = limits or ABSURD_LIMITS
    low, high = (np.array([limits[key][i] for key in MEASUREMENTS], dtype=float) for i in (0, 1))
    with np.errstate(invalid="ignore"):
        good = np.isfinite(requests) & (requests > 0.0) & (requests >= low) & (requests <= high)
    if not np.all(good):
        row = int(np.argwhere(~good)[0][0])
        try:
            validate_request([float(v) for v in requests[row]], ranges, limits)
        except MeasurementError as error:
            raise MeasurementError(error.field, f"row {row}: {str(error).partition(': ')[2]}") from None
    return requests
