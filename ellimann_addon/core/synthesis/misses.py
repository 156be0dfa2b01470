"""What exact mode missed, as data: a measurement further from its request than exact mode's criterion (the five
beyond ``EXACT_TOLERANCE``, relative, where refinement stops; a given extra measurement beyond ``MISS_CM``), with
what it came to and what was asked. ``synth``, ``batch``, ``demo`` and the panel judge and word misses by these
alone."""

import math
from dataclasses import dataclass

from ..measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from .refine import EXACT_TOLERANCE

MISS_CM = 0.1  # a given extra measurement further off than this (1 mm) is a miss
SKIN_MISS_CM = 0.1  # a measurement a skin's mesh misses by more than this (1 mm) in exact mode is a miss


@dataclass(frozen=True)
class Miss:
    """One requested measurement exact mode did not meet: its key, what the mannequin measures and what was asked
    (cm)."""

    key: str
    measured: float
    requested: float

    @property
    def off_cm(self):
        """Signed: positive when the mannequin measures more than asked."""
        return self.measured - self.requested

    @property
    def error_pct(self):
        return abs(self.off_cm) / self.requested * 100.0

    def describe(self):
        """ "Sh by 2.64% (m_T 32.81 cm for 31.97 cm)"; an extra measurement's by its distance in cm."""
        if self.key in MEASUREMENTS:
            return f"{self.key} by {self.error_pct:.2f}% (m_T {self.measured:.2f} cm for {self.requested:g} cm)"
        return f"{self.key} by {self.off_cm:+.2f} cm ({self.measured:.2f} cm for {self.requested:g} cm)"


def five_missed(measured, requested):
    """Whether m_T ``measured`` misses ``requested`` (cm) by more than EXACT_TOLERANCE, the criterion exact mode
    stops at (the log of their ratio, as the refinement measures it)."""
    return abs(math.log(max(float(measured), 1e-12) / float(requested))) > EXACT_TOLERANCE


def request_misses(measured, requested, extra=None, mode="exact"):
    """The misses (:class:`Miss`, in the order of MEASUREMENTS and EXTRA_MEASUREMENTS) of a mannequin
    measuring ``measured`` ({key: cm}: the five, and the extra ones it was asked for) against the five
    ``requested`` (dict or 5 values, cm) and the ``extra`` ones asked ({key: cm}). IDW (``mode`` "idw") promises no
    match, so it misses nothing."""
    if mode != "exact":
        return []
    if not isinstance(requested, dict):
        requested = dict(zip(MEASUREMENTS, requested))
    missed = [
        Miss(key, float(measured[key]), float(requested[key]))
        for key in MEASUREMENTS
        if five_missed(measured[key], requested[key])
    ]
    extra = extra or {}
    missed += [
        Miss(key, float(measured[key]), float(extra[key]))
        for key in EXTRA_MEASUREMENTS
        if key in extra and abs(measured[key] - extra[key]) > MISS_CM
    ]
    return missed


def missed_text(missed):
    """One line for every miss of a mannequin: "exact mode missed Sh by 2.64% (m_T 32.81 cm for 31.97 cm), neck by
    +1.10 cm (36.10 cm for 35 cm) (tolerance 0.001%; ...)"."""
    extra = any(miss.key not in MEASUREMENTS for miss in missed)
    return (
        "exact mode missed "
        + ", ".join(miss.describe() for miss in missed)
        + f" (tolerance {EXACT_TOLERANCE * 100:g}%"
        + (f", the extra measurements {MISS_CM * 10:g} mm" if extra else "")
        + "; the mannequin is the closest it found)"
    )


def skin_misses(measured, requested):
    """The measurements asked (``requested``, {key: cm}: the five and the extra ones) that a skin measuring
    ``measured`` on its mesh misses by more than SKIN_MISS_CM, as :class:`Miss`."""
    return [
        Miss(key, float(measured[key]), float(wanted))
        for key, wanted in requested.items()
        if abs(measured[key] - wanted) > SKIN_MISS_CM
    ]


def skin_missed_text(missed, rounds):
    """One line for a skin's misses: "exact mode on the skin missed Br by +0.12 cm (skin 101.13 cm for 101.25 cm)
    (tolerance 1 mm on its mesh; the closest skin found in 3 rounds)"."""
    return (
        "exact mode on the skin missed "
        + ", ".join(
            f"{miss.key} by {miss.off_cm:+.2f} cm (skin {miss.measured:.2f} cm for {miss.requested:g} cm)"
            for miss in missed
        )
        + f" (tolerance {SKIN_MISS_CM * 10:g} mm on its mesh; the closest skin found in {rounds} rounds)"
    )
