"""The correction: the body model's body deformed (core.body.deform) until the tape (core.body.tape) reads the
request, within AIM_CM, on every measurement asked.

Each measurement has its own parameter, and each parameter moves its measurement most: the first Jacobian is
the diagonal the deformations give in closed form (a horizontal scale by c scales the girth at its section by
1 + c, a vertical one the height, moving both arms by t widens the shoulders by 2t), then Broyden's update
learns how they couple (the legs' stretch moves the hip's section; the trunk's scales move the shoulders). A
step never moves a parameter by more than MAX_STEP of its limit. Nothing here compares last bits: the loop stops
on a tolerance with a margin (AIM_CM, a fifth of the promise), and any tape reading is a plain measurement of
a mesh whose vertices move smoothly with the parameters.

A request the bodies cannot plausibly reach (a parameter beyond LIMITS: a girth scaled by more than a quarter,
shoulders widened by more than 6 cm a side, ...) is refused in one line naming the measurement, the request, what
the bodies' blend measures and the factor it would take.
"""

from dataclasses import dataclass

import numpy as np

from ..constants import CM_PER_M
from ..errors import ElliMannError
from .deform import PARAMETERS

PROMISE_CM = 0.1  # what a body skin measures within: 1 mm
AIM_CM = 0.02  # the loop's aim: a fifth of the promise
MAX_ROUNDS = 14
# the largest plausible parameter: relative scales (He, the girths, crotch height, arm length), metres (Sh a side)
LIMITS = {key: 0.45 for key in PARAMETERS} | {"He": 0.2, "crotch_height": 0.2, "arm_length": 0.2, "Sh": 0.06}
MAX_STEP = 0.5  # of a parameter's limit per round
SLOPE_RANGE = (0.25, 4.0)  # a learned diagonal slope stays within these multiples of the closed form's


class BodySkinError(ElliMannError):
    """A body skin that cannot be made: a request beyond the bodies, a mesh that would fold, bad bodies."""


@dataclass
class Correction:
    """The parameters ``theta`` (K,) found, the tape's reading ``measured`` ({key: cm}), ``start`` (what the body
    model's body measured), ``rounds`` and whether every key is within PROMISE_CM (``converged``)."""

    theta: np.ndarray
    measured: dict
    start: dict
    rounds: int
    converged: bool


def closed_form_slopes(deformation, start):
    """(K,) cm per unit of each parameter at the start, from the deformations' closed forms."""
    slopes = {key: start.get(key, 100.0) for key in PARAMETERS}  # a scale by c adds c times the measurement
    slopes["Sh"] = 2.0 * CM_PER_M  # both arms out by t metres
    ramp = np.abs(deformation.basis[PARAMETERS.index("crotch_height"), :, 2]).max()
    slopes["crotch_height"] = max(ramp * CM_PER_M, 1.0)
    return np.array([slopes[key] for key in PARAMETERS])


def describe(key, factor):
    if key == "Sh":
        return f"move each arm {abs(factor) * 100:.1f} cm {'out' if factor > 0 else 'in'}"
    return f"scale it by {1.0 + factor:.2f}"


def refuse(key, theta, request, start):
    limit = LIMITS[key]
    bound = f"{limit * 100:.0f} cm a side" if key == "Sh" else f"{1 - limit:.2f} to {1 + limit:.2f}"
    return BodySkinError(
        f"body skin: {key} {request[key]:.1f} cm is {request[key] - start[key]:+.1f} cm from what the set's bodies "
        f"give for this request ({start[key]:.1f} cm): the correction would {describe(key, theta)} "
        f"(at most {bound}); ask nearer the set's bodies or use the pieces' skin"
    )


def correct(deformation, tape, request, neck_tilt=None, max_rounds=MAX_ROUNDS, aim=AIM_CM):
    """The Correction of ``deformation``'s body to ``request`` ({key: cm} of PARAMETERS), read by ``tape``.
    BodySkinError for a request beyond the bodies' plausible reach."""
    keys = [key for key in PARAMETERS if key in request]
    index = np.array([PARAMETERS.index(key) for key in keys])
    target = np.array([request[key] for key in keys])
    limits = np.array([LIMITS[key] for key in keys])
    theta = np.zeros(len(PARAMETERS))
    start = tape.measure(deformation.rest, keys, neck_tilt)
    reading = np.array([start[key] for key in keys])
    closed = closed_form_slopes(deformation, start)[index]
    jacobian = np.diag(closed)
    rounds = 0
    for rounds in range(1, max_rounds + 1):
        residual = target - reading
        if np.all(np.abs(residual) <= aim):
            rounds -= 1
            break
        try:
            step = np.linalg.solve(jacobian, residual)
        except np.linalg.LinAlgError:
            step = residual / closed
        step = np.clip(step, -MAX_STEP * limits, MAX_STEP * limits)
        trial = theta.copy()
        trial[index] += step
        beyond = np.abs(trial[index]) > 1.5 * limits
        if beyond.any():
            k = int(np.argmax(np.abs(trial[index]) / limits))
            raise refuse(keys[k], trial[index][k], request, start)
        found = tape.measure(deformation.apply(trial)[0], keys, neck_tilt)
        new = np.array([found[key] for key in keys])
        if not np.all(np.isfinite(new)):
            missing = [key for key, value in zip(keys, new) if not np.isfinite(value)]
            raise BodySkinError(f"body skin: {', '.join(missing)} cannot be measured on the corrected body")
        change = new - reading
        # Broyden's update, its diagonal kept within SLOPE_RANGE of the closed form
        jacobian = jacobian + np.outer(change - jacobian @ step, step) / float(step @ step)
        diagonal = np.clip(np.diag(jacobian), SLOPE_RANGE[0] * closed, SLOPE_RANGE[1] * closed)
        np.fill_diagonal(jacobian, diagonal)
        theta, reading = trial, new
    for k, key in enumerate(keys):
        if abs(theta[index[k]]) > limits[k]:
            raise refuse(key, theta[index[k]], request, start)
    measured = dict(zip(keys, reading.tolist()))
    converged = bool(np.all(np.abs(target - reading) <= PROMISE_CM))
    return Correction(theta, measured, start, rounds, converged)
