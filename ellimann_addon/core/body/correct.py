"""The correction: the body model's body deformed (core.body.deform) until the tape (core.body.tape) reads the
request, within AIM_CM, on every measurement asked.

Each measurement has its own parameter, and each parameter moves its measurement most: the first Jacobian is
the diagonal the deformations give in closed form (a horizontal scale by c scales the girth at its section by
about 1 + c, a vertical one the height, moving both arms by t widens the shoulders by 2t), then Broyden's update
learns how they couple (the legs' stretch moves the hip's section; the trunk's scales move the shoulders). A
step never moves a parameter by more than MAX_STEP of its SCALE. Nothing here compares last bits: the loop stops
on a tolerance with a margin (AIM_CM, a fifth of the promise), and any tape reading is a plain measurement of
a mesh whose vertices move smoothly with the parameters.

There is no limit on a parameter here but BOUNDS, far beyond any body (a section scaled by half or twice, exact
mode's limit on a piece): what a body skin may become is judged on the corrected mesh (core.body.plausible),
which names the measurement and how far the body skin reaches. A correction that leaves BOUNDS stops there,
``beyond`` naming the parameter.
"""

from dataclasses import dataclass

import numpy as np

from ..constants import CM_PER_M
from ..errors import ElliMannError
from .deform import PARAMETERS

PROMISE_CM = 0.1  # what a body skin measures within: 1 mm
AIM_CM = 0.02  # the loop's aim: a fifth of the promise
MAX_ROUNDS = 14
# a parameter's scale (relative scales: He, the girths, crotch height, arm length; metres a side: Sh), for steps
SCALES = {key: 0.45 for key in PARAMETERS} | {"He": 0.2, "crotch_height": 0.2, "arm_length": 0.2, "Sh": 0.06}
MAX_STEP = 0.5  # of a parameter's scale per round
# (low, high) no body's correction goes beyond: a section, a limb or a length scaled by half or twice; the arms
# moved by 15 cm a side
BOUNDS = {key: (-0.5, 1.0) for key in PARAMETERS} | {"Sh": (-0.15, 0.15)}
SLOPE_RANGE = (0.25, 4.0)  # a learned diagonal slope stays within these multiples of the closed form's


class BodySkinError(ElliMannError):
    """A body skin that cannot be made: a request beyond the bodies, a mesh that would fold, bad bodies."""


@dataclass
class Correction:
    """The parameters ``theta`` (K,) found, the tape's reading ``measured`` ({key: cm}), ``start`` (what the body
    model's body measured), ``rounds``, whether every key is within PROMISE_CM (``converged``) and the parameter
    that left its BOUNDS (``beyond``, or None)."""

    theta: np.ndarray
    measured: dict
    start: dict
    rounds: int
    converged: bool
    beyond: str = None


def closed_form_slopes(deformation, start):
    """(K,) cm per unit of each parameter at the start, from the deformations' closed forms."""
    slopes = {key: start.get(key, 100.0) for key in PARAMETERS}  # a scale by c adds c times the measurement
    slopes["Sh"] = 2.0 * CM_PER_M  # both arms out by t metres
    ramp = np.abs(deformation.basis[PARAMETERS.index("crotch_height"), :, 2]).max()
    slopes["crotch_height"] = max(ramp * CM_PER_M, 1.0)
    return np.array([slopes[key] for key in PARAMETERS])


def correct(deformation, read, request, max_rounds=MAX_ROUNDS, aim=AIM_CM, theta=None, start=None):
    """The Correction of ``deformation``'s body to ``request`` ({key: cm} of PARAMETERS), ``read(vertices)`` giving
    {key: cm}: not ``converged`` with ``beyond`` naming the parameter when it would leave BOUNDS. From ``theta``
    (default none) and its reading ``start`` (default read). BodySkinError when a measurement cannot be taken on
    the corrected body."""
    keys = [key for key in PARAMETERS if key in request]
    index = np.array([PARAMETERS.index(key) for key in keys])
    target = np.array([request[key] for key in keys])
    scales = np.array([SCALES[key] for key in keys])
    low, high = (np.array([BOUNDS[key][i] for key in keys]) for i in (0, 1))
    theta = np.zeros(len(PARAMETERS)) if theta is None else np.array(theta, float)
    start = start or read(deformation.apply(theta)[0])
    reading = np.array([start[key] for key in keys])
    closed = closed_form_slopes(deformation, start)[index]
    jacobian = np.diag(closed)
    rounds, beyond = 0, None
    for rounds in range(1, max_rounds + 1):
        residual = target - reading
        if np.all(np.abs(residual) <= aim):
            rounds -= 1
            break
        try:
            step = np.linalg.solve(jacobian, residual)
        except np.linalg.LinAlgError:
            step = residual / closed
        step = np.clip(step, -MAX_STEP * scales, MAX_STEP * scales)
        trial = theta.copy()
        trial[index] = np.clip(theta[index] + step, low, high)
        if np.all(trial == theta):  # pinned at a bound
            k = int(np.argmax(np.abs(residual / closed) * ((theta[index] <= low) | (theta[index] >= high))))
            beyond = keys[k]
            break
        step = trial[index] - theta[index]
        found = read(deformation.apply(trial)[0])
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
    measured = dict(zip(keys, reading.tolist()))
    converged = bool(np.all(np.abs(target - reading) <= PROMISE_CM))
    if not converged and beyond is None:
        at_bound = (theta[index] <= low) | (theta[index] >= high)
        if at_bound.any():
            beyond = keys[int(np.argmax(np.abs(target - reading) * at_bound))]
    return Correction(theta, measured, start, rounds, converged, beyond)
