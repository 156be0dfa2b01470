"""A batch in chunks: a stream of rows cut into consecutive chunks (:func:`chunks`), each chunk's rows of one reference
set (:func:`by_reference_set`) synthesized in one core batch, the rows a batch refuses synthesized alone, and each row's
extra measurements met as ``synth`` meets them (:func:`synthesize_chunk`). The result is a ``SynthesizedBatch`` with an
error per row: what a Dask worker sends back. ``ellimann batch`` runs the chunks in the CSV's order, serially or on
Dask, and streams what they give into its files."""

import math

import numpy as np

from ..errors import ElliMannError, one_line
from ..measure.tailor import as_dict
from ..measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from .synthesize import SynthesizedBatch, meet_extra_request, synthesize_checked

CHUNK = 256  # rows synthesized per core batch (and per Dask task)
_FIELDS = ("rotation", "center", "semi_axes", "measured", "factors", "converged", "joints")


def chunks(items, size=None):
    """Consecutive lists of ``size`` (default CHUNK) items of an iterable (the last one shorter), read as they are
    needed."""
    size, chunk = size or CHUNK, []
    for item in items:
        chunk.append(item)
        if len(chunk) == size:
            yield chunk
            chunk = []
    if chunk:
        yield chunk


def by_reference_set(references):
    """The positions of a chunk's rows grouped by their reference sets (``references``, one per row), the sets in
    the order they first appear: [(set, [positions])]. Sets are told apart by identity (each is loaded once)."""
    groups = {}
    for position, reference in enumerate(references):
        groups.setdefault(id(reference), (reference, []))[1].append(position)
    return list(groups.values())


def synthesize_chunk(reference, requests, options, extras=None):
    """Rows of one reference set synthesized in one core batch (what a Dask task runs): ``requests`` (B, 5) cm and
    ``options``, both checked where they entered (``checked_request``, ``SynthesisOptions.checked``); ``extras``:
    per row the extra measurements it asks for ({key: cm}, checked by ``extra_request_problems``; empty: none),
    met as ``synth`` meets them (``meet_extra_request``), the rows' arrays then those of the mannequin that meets
    them. If the batch refuses a row (an implausible body), every row is synthesized alone, so only that row
    fails: batched and one-at-a-time results are the same bits. Returns a SynthesizedBatch with ``errors`` per row
    (and ``extra_measured`` when a row asked for extra measurements)."""
    requests = np.asarray(requests, dtype=float).reshape(-1, len(MEASUREMENTS))
    try:
        result = synthesize_checked(reference, requests, options)
        result.errors = [None] * len(requests)
    except ElliMannError:
        result = _one_at_a_time(reference, requests, options)
    if extras and any(extras):
        _meet_extras(result, extras, options.mode)
    return result


def _one_at_a_time(reference, requests, options):
    """:func:`synthesize_chunk`'s rows synthesized alone, a refused row's error kept and its arrays NaN."""
    parts, errors = [], []
    for values in requests:
        try:
            parts.append(synthesize_checked(reference, values[None], options))
            errors.append(None)
        except ElliMannError as error:
            parts.append(None)
            errors.append(one_line(error))
    good = next((part for part in parts if part is not None), None)
    if good is None:
        return failed_chunk(reference, requests, errors, options.mode)
    arrays = {}
    for key in _FIELDS:
        if getattr(good, key) is None:
            arrays[key] = None
            continue
        arrays[key] = np.concatenate([getattr(part if part is not None else good, key) for part in parts])
        failed = [i for i, part in enumerate(parts) if part is None]
        arrays[key][failed] = False if key == "converged" else np.nan
    return SynthesizedBatch(
        good.topology,
        requests,
        mode=good.mode,
        reference_set=good.reference_set,
        section_fractions=good.section_fractions,
        errors=errors,
        **arrays,
    )


def failed_chunk(reference, requests, errors, mode):
    """A SynthesizedBatch of ``requests`` in which every row failed (``errors``: one line each), its arrays NaN."""
    count, parts = len(requests), len(reference.topology)
    return SynthesizedBatch(
        reference.topology,
        np.asarray(requests, dtype=float).reshape(count, len(MEASUREMENTS)),
        np.full((count, parts, 3, 3), np.nan),
        np.full((count, parts, 3), np.nan),
        np.full((count, parts, 3), np.nan),
        np.full((count, len(MEASUREMENTS)), np.nan),
        np.full((count, len(MEASUREMENTS)), np.nan),
        np.zeros(count, dtype=bool),
        mode,
        reference.name,
        reference.section_fractions,
        errors=list(errors),
    )


def _meet_extras(result, extras, mode):
    """Each row of ``result`` that asks for extra measurements given them (``meet_extra_request``), in place: its
    arrays and m_T those of the mannequin meeting them, ``extra_measured`` what they come to."""
    result.extra_measured = np.full((len(result), len(EXTRA_MEASUREMENTS)), np.nan)
    for i, extra in enumerate(extras):
        if not extra or result.error(i) is not None:
            continue
        try:
            mannequin, measured, _ = meet_extra_request(result.mannequin(i), as_dict(result.measured[i]), extra, mode)
        except ElliMannError as error:  # that row's, as a refused synthesis is
            result.errors[i] = one_line(error)
            continue
        result.rotation[i], result.center[i], result.semi_axes[i] = (
            mannequin.rotation,
            mannequin.center,
            mannequin.semi_axes,
        )
        if result.joints is not None:
            result.joints[i] = mannequin.joints
        result.measured[i] = [measured[key] for key in MEASUREMENTS]
        result.extra_measured[i] = [measured[key] if key in extra else math.nan for key in EXTRA_MEASUREMENTS]
