"""Adjusting a mannequin so that its m_T hits requested tailor measurements.

Each measurement has one control, a stretch of the parts that make it:

- He: every part stretched vertically about the lowest point (heights scale, the section
  heights follow since they are fractions of He);
- Sh: the parts that depend on Sh move outwards along X: in proportion to their distance from the
  sagittal plane up to the shoulder point (half the shoulder width), by the shoulder point's own
  shift beyond it, so the shoulder girdle widens and the arms move with the shoulders unchanged;
- Br, Wa, Hi: the girth parts that cross the section stretched horizontally about the vertical
  axis through the section's centre. A part crossing several sections takes the geometric mean of
  their factors.

Stretches keep every ellipsoid's frame (so axis labels stay consistent across mannequins) and
scale each semi-axis by the length of its stretched direction; this is the exact affine image when
the axis lies along a world axis and a close approximation for tilted parts. The controls are
coupled a little (a part may cross two sections, a horizontal stretch of a tilted part moves its top
a little), so the five factors are solved together by Newton's method on log(m_T / target) with a
finite-difference Jacobian: all in closed form and deterministic.

Used to make the Reference Mannequins meet Table 2.3, and reusable wherever a mannequin close to
the request must hit it exactly (e.g. synthesis' exact mode).
"""

import math
from dataclasses import dataclass

import numpy as np

from .constants import CM_PER_M, GIRTHS, MEASUREMENTS
from .ellipsoid import section_at_height
from .errors import MeasurementError
from .measure import section_heights, tailor_measurements

FD_STEP = 1e-5  # log-factor step of the finite-difference Jacobian
MAX_HALVINGS = 8  # backtracking steps when a Newton step does not reduce the error


def stretch(rotation, center, semi_axes, scale, origin):
    """Stretch ellipsoids by world-axis factors about origins, keeping their frames.

    ``scale`` (..., 3) factors along world X, Y, Z and ``origin`` (..., 3), broadcast against the
    ellipsoids (n, ...). The centre maps to ``origin + scale * (center - origin)``; semi-axis i becomes
    ``D_i * |diag(scale) R[:, i]|``. Returns (rotation, center, semi_axes); rotation is unchanged.
    """
    rotation = np.asarray(rotation, dtype=float)
    scale = np.asarray(scale, dtype=float)
    origin = np.asarray(origin, dtype=float)
    center = origin + scale * (np.asarray(center, dtype=float) - origin)
    lengths = np.linalg.norm(rotation * scale[..., :, None], axis=-2)
    return rotation, center, np.asarray(semi_axes, dtype=float) * lengths


@dataclass(frozen=True)
class Controls:
    """Which parts each control moves, fixed from the starting mannequin.

    ``crossing`` (3, n) bool: the girth parts cut by the Br, Wa, Hi sections; ``section_y`` (3,) the
    y of each section's centre (midpoint of its extent along Y); ``shoulder`` (n,) bool: the parts
    that depend on Sh; ``shoulder_x`` half the shoulder width; ``floor`` the lowest point's z.
    """

    crossing: np.ndarray
    section_y: np.ndarray
    shoulder: np.ndarray
    shoulder_x: float
    floor: float

    @classmethod
    def of(cls, mannequin):
        rotation, center, semi_axes = mannequin.rotation, mannequin.center, mannequin.semi_axes
        girth = mannequin.topology.girth_mask
        floor, _, heights = section_heights(rotation, center, semi_axes)
        crossing, section_y = [], []
        for key in GIRTHS:
            centre2, k, hit = section_at_height(rotation, center, semi_axes, heights[key])
            active = hit & girth
            crossing.append(active)
            if active.any():
                half_y = np.sqrt(k[active, 1, 1])
                section_y.append(0.5 * ((centre2[active, 1] + half_y).max() + (centre2[active, 1] - half_y).min()))
            else:
                section_y.append(0.0)
        shoulder = mannequin.topology.dependency_mask[:, MEASUREMENTS.index("Sh")]
        shoulder_x = 0.5 * mannequin.measure()["Sh"] / CM_PER_M
        return cls(np.array(crossing), np.array(section_y), shoulder, shoulder_x, float(floor))

    def apply(self, mannequin, log_factors):
        """The mannequin stretched by exp(log_factors), a (5,) array in MEASUREMENTS order."""
        factors = dict(zip(MEASUREMENTS, np.exp(np.asarray(log_factors, dtype=float))))
        rotation, center, semi_axes = mannequin.rotation, mannequin.center, mannequin.semi_axes
        n = len(center)

        # Girth sections: per part, the geometric mean of the factors of the sections it crosses.
        count = self.crossing.sum(axis=0)
        log_girth = np.array([math.log(factors[key]) for key in GIRTHS])
        mean_log = np.divide(log_girth @ self.crossing, count, out=np.zeros(n), where=count > 0)
        mean_y = np.divide(self.section_y @ self.crossing, count, out=np.zeros(n), where=count > 0)
        horizontal = np.exp(mean_log)
        scale = np.stack([horizontal, horizontal, np.ones(n)], axis=-1)
        origin = np.stack([np.zeros(n), mean_y, np.zeros(n)], axis=-1)
        rotation, center, semi_axes = stretch(rotation, center, semi_axes, scale, origin)

        center = center.copy()
        x = center[self.shoulder, 0]
        center[self.shoulder, 0] += (factors["Sh"] - 1.0) * np.sign(x) * np.minimum(np.abs(x), self.shoulder_x)

        rotation, center, semi_axes = stretch(rotation, center, semi_axes, np.array([1.0, 1.0, factors["He"]]),
                                              np.array([0.0, 0.0, self.floor]))
        return mannequin.copy(rotation=rotation, center=center, semi_axes=semi_axes)


@dataclass
class Adjustment:
    """Result of :func:`adjust_to_measurements`."""

    mannequin: object
    measured: dict  # m_T (cm) of ``mannequin``
    factors: dict  # the stretch factor of each control
    iterations: int
    converged: bool

    def relative_errors(self, targets):
        return {key: self.measured[key] / targets[key] - 1.0 for key in targets}


def check_targets(targets):
    """Refuse targets that are not positive, finite measurements named in MEASUREMENTS."""
    if not isinstance(targets, dict) or not targets:
        raise MeasurementError("targets", f"must be a dict of measurements ({', '.join(MEASUREMENTS)}) in cm")
    for key, value in targets.items():
        if key not in MEASUREMENTS:
            raise MeasurementError(str(key), f"is not a measurement; expected one of {', '.join(MEASUREMENTS)}")
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
            raise MeasurementError(key, f"must be a positive number of cm, got {value!r}")


def adjust_to_measurements(mannequin, targets, tolerance=1e-4, max_iterations=20):
    """Stretch ``mannequin`` so that m_T meets ``targets`` (cm; any subset of MEASUREMENTS).

    Measurements not in ``targets`` keep their control at factor 1 (they still move a little when
    the others do). Stops when every targeted relative error is at most ``tolerance`` or after
    ``max_iterations`` Newton steps; ``converged`` tells which. Raises MeasurementError for bad
    targets or when a targeted measurement is 0 (no part crosses its section).
    The input is not changed.
    """
    check_targets(targets)
    keys = [key for key in MEASUREMENTS if key in targets]
    rows = np.array([MEASUREMENTS.index(key) for key in keys])
    goal = np.log(np.array([targets[key] for key in keys], dtype=float))
    controls = Controls.of(mannequin)

    def residuals(log_factors_batch):
        batch = [controls.apply(mannequin, p) for p in log_factors_batch]
        measured = tailor_measurements(np.stack([m.rotation for m in batch]), np.stack([m.center for m in batch]),
                                       np.stack([m.semi_axes for m in batch]), mannequin.topology.girth_mask)
        values = measured[:, rows]
        if np.any(values <= 0.0):
            key = keys[int(np.argmax(np.any(values <= 0.0, axis=0)))]
            raise MeasurementError(key, "is 0 on this mannequin: no part crosses its section, nothing to adjust")
        return np.log(values) - goal, batch, measured

    log_factors = np.zeros(len(MEASUREMENTS))
    r, batch, measured = residuals([log_factors])
    r, current, measured = r[0], batch[0], measured[0]
    iterations = 0
    while np.max(np.abs(np.expm1(r))) > tolerance and iterations < max_iterations:
        iterations += 1
        probes = [log_factors + FD_STEP * np.eye(len(MEASUREMENTS))[row] for row in rows]
        r_probe, _, _ = residuals(probes)
        jacobian = (r_probe - r).T / FD_STEP  # (keys, controls)
        step = np.linalg.lstsq(jacobian, -r, rcond=None)[0]
        for _ in range(MAX_HALVINGS + 1):
            trial = log_factors.copy()
            trial[rows] += step
            r_trial, batch, m_trial = residuals([trial])
            if np.max(np.abs(r_trial[0])) < np.max(np.abs(r)):
                log_factors, r, current, measured = trial, r_trial[0], batch[0], m_trial[0]
                break
            step = 0.5 * step
        else:
            break
    converged = bool(np.max(np.abs(np.expm1(r))) <= tolerance)
    return Adjustment(current, dict(zip(MEASUREMENTS, map(float, measured))),
                      dict(zip(MEASUREMENTS, map(float, np.exp(log_factors)))), iterations, converged)
