"""A batch in chunks: each chunk of requests synthesized in one core batch, the rows a batch refuses synthesized
alone (:func:`synthesize_chunk`), and the chunk's result as plain arrays with an error per row
(:class:`ChunkResult`, what a Dask worker sends back). ``ellimann batch`` runs the chunks serially or on Dask."""

import numpy as np

from ..errors import ElliMannError, one_line
from ..mannequin.model import Mannequin
from ..measure.tailor import as_dict
from .synthesize import synthesize_batch

CHUNK = 256  # rows synthesized per core batch (and per Dask task)


def synthesize_chunk(reference, requests, options):
    """A chunk of requests synthesized in one core batch (what a Dask task runs). If the batch refuses a row
    (an implausible body), every row is synthesized alone, so only that row fails: batched and one-at-a-time
    results are the same bits. Returns a ChunkResult."""
    try:
        return ChunkResult.of(synthesize_batch(reference, requests, options), [None] * len(requests))
    except ElliMannError:
        pass
    parts, errors = [], []
    for values in requests:
        try:
            parts.append(synthesize_batch(reference, [values], options))
            errors.append(None)
        except ElliMannError as error:
            parts.append(None)
            errors.append(one_line(error))
    return ChunkResult.joined(parts, errors)


def set_landmarks(synthesis):
    """What each mannequin of a Synthesis records of its reference set (Mannequin keywords)."""
    return {"reference_set": synthesis.reference_set, "section_fractions": synthesis.section_fractions}


class ChunkResult:
    """A chunk's synthesis as plain arrays (what a Dask worker sends back): ``errors[i]`` is None or why row i
    failed (its arrays are then NaN)."""

    FIELDS = ("rotation", "center", "semi_axes", "measured", "factors", "converged")

    def __init__(self, topology, errors, joints=None, landmarks=None, **arrays):
        self.topology, self.errors = topology, errors
        self.joints = joints  # (B, 24, 3) or None: the reference set has no joints
        self.landmarks = landmarks or {}  # the set's name and section heights, which each mannequin records
        for key in self.FIELDS:
            setattr(self, key, arrays[key])

    @classmethod
    def of(cls, synthesis, errors):
        return cls(
            synthesis.topology,
            errors,
            synthesis.joints,
            set_landmarks(synthesis),
            **{key: getattr(synthesis, key) for key in cls.FIELDS},
        )

    @classmethod
    def joined(cls, parts, errors):
        good = next((p for p in parts if p is not None), None)
        if good is None:
            return cls(None, errors, **{key: [None] * len(parts) for key in cls.FIELDS})
        arrays = {
            key: np.concatenate([getattr(p if p is not None else good, key) for p in parts]) for key in cls.FIELDS
        }
        joints = None if good.joints is None else np.concatenate([(p if p is not None else good).joints for p in parts])
        for i, part in enumerate(parts):
            if part is None:
                for key in cls.FIELDS:
                    if key != "converged":
                        arrays[key][i] = np.nan
                arrays["converged"][i] = False
                if joints is not None:
                    joints[i] = np.nan
        return cls(good.topology, errors, joints, set_landmarks(good), **arrays)

    def mannequin(self, i, name, request):
        return Mannequin(
            self.topology,
            self.rotation[i],
            self.center[i],
            self.semi_axes[i],
            name=name,
            role="synthesized",
            measurements=as_dict(request),
            joints=None if self.joints is None else self.joints[i],
            **self.landmarks,
        )
