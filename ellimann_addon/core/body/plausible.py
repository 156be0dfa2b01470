"""What a corrected body may become: the body skin's plausibility, judged on the mesh rather than on the
correction's parameters, and how far a refused request's measurement could go (its reach).

A body cannot:
- fold over: triangles turned over or crushed by the correction (core.body.mesh_checks.fold_problems);
- be stretched or squeezed out of its own shape: a triangle's principal stretch from the body model's body beyond
  STRETCH_RANGE (half or twice, exact mode's limit on a piece: it would no longer look like itself), allowed for
  STRETCH_ALLOWANCE of the triangles (crease triangles of a few millimetres);
- have its arms through its trunk: an arm's section inside the trunk's by more than INTRUSION_TOLERANCE at the
  heights between the hands and the armpits. The arms are first raised sideways about the shoulders (a pose, by
  at most MAX_ABDUCTION: core.body.deform.abducted) until they clear it, as a person with narrow shoulders over a
  wide trunk holds them.

Before any of that, a request's proportions: between two neighbouring girth sections the trunk's girth changes
with height as a body's can, its taper ((upper girth - lower girth) / (2 pi x their distance), the slope of an
equally round trunk's side) within TAPERS, the extremes of the 170 bodies of one body model (the 80 + 80 of
../shared/bodies and the sets' 5 + 5) widened by TAPER_MARGIN: a 153 cm bust over a 63 cm waist 11 cm below it
(taper 1.3), or a 142 cm waist over 83 cm hips (-0.4), is no body. The six extras keep exact mode's rules
(core.synthesis.extra_refine: a thigh smaller than the hips, ...).

A problem blames the measurement whose deformation moves the offending triangles most; its reach is found by
bisection between what the bodies give and the request, the rest of the request kept.
"""

import numpy as np

from ..measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ..synthesis.extra_refine import extra_request_problems
from .deform import PARAMETERS
from .mesh_checks import FOLD_ALLOWANCE, fold_problems, principal_stretches

# (upper, lower) section: the trunk's taper between them, (low, high) over the 170 bodies (female Br/Wa -0.22 to
# 0.57, male 0.02 to 0.32; Wa/Hi female -0.30 to -0.01, male -0.22 to 0.02)
TAPERS = {("Br", "Wa"): (-0.22, 0.57), ("Wa", "Hi"): (-0.30, 0.02)}
TAPER_MARGIN = 0.15  # beyond the bodies' extremes (their spread's sd: 0.05-0.13)
STRETCH_RANGE = (0.5, 2.0)
STRETCH_ALLOWANCE = FOLD_ALLOWANCE  # of the triangles
INTRUSION_TOLERANCE = 0.002  # m
MAX_ABDUCTION = np.radians(20.0)
ABDUCTION_MARGIN = 0.005  # m beyond the intrusion's depth the arms are raised to clear
REACH_STEPS = 6  # bisection steps: the reach within 1/64 of the way from the bodies' value to the request


def proportion_problem(request, fractions):
    """(line, blamed key) when the request's trunk tapers between two neighbouring sections beyond what a body
    can (TAPERS widened by TAPER_MARGIN), or its extras break exact mode's rules; (None, None) otherwise."""
    for (upper, lower), (low, high) in TAPERS.items():
        distance = (fractions[upper] - fractions[lower]) * request["He"]  # cm
        taper = (request[upper] - request[lower]) / (2.0 * np.pi * distance)
        low, high = low - TAPER_MARGIN, high + TAPER_MARGIN
        if low <= taper <= high:
            continue
        bound = high if taper > high else low
        girth = request[lower] + bound * 2.0 * np.pi * distance  # the upper girth at the bound
        other = request[upper] - bound * 2.0 * np.pi * distance
        line = (
            f"{upper} {request[upper]:.1f} cm over {lower} {request[lower]:.1f} cm {distance:.1f} cm below: the trunk "
            f"would taper by {taper:+.2f} (girth / 2 pi per cm of height; bodies {low + TAPER_MARGIN:+.2f} to "
            f"{high - TAPER_MARGIN:+.2f}, allowed {low:+.2f} to {high:+.2f}): {upper} "
            f"{'at most' if taper > high else 'at least'} {girth:.1f} cm with this {lower}, or {lower} "
            f"{'at least' if taper > high else 'at most'} {other:.1f} cm with this {upper}"
        )
        return line, upper
    extras = {key: value for key, value in request.items() if key in EXTRA_MEASUREMENTS}
    if extras:
        problems = extra_request_problems({key: request[key] for key in MEASUREMENTS}, extras)
        if problems:
            return problems[0], problems[0].split()[0]
    return None, None


def stretch_problem(before, after, faces):
    """(line, bad triangle mask) when more than STRETCH_ALLOWANCE of the triangles are stretched or squeezed
    beyond STRETCH_RANGE (None, None otherwise)."""
    small, large = principal_stretches(before, after, faces)
    low, high = STRETCH_RANGE
    bad = (small < low) | (large > high)
    if bad.sum() <= STRETCH_ALLOWANCE * len(faces):
        return None, None
    z = after[faces[bad]].mean(axis=1)[:, 2]
    bottom, height = after[:, 2].min(), np.ptp(after[:, 2])
    where = f"{(z.min() - bottom) / height:.2f}-{(z.max() - bottom) / height:.2f} He"
    line = (
        f"{int(bad.sum())} triangles would be stretched beyond {high:g}x or squeezed below {low:g}x their size "
        f"(to {large[bad].max():.2f}x and {small[bad].min():.2f}x, at {where})"
    )
    return line, bad


def surface_problem(before, after, faces, allowance=FOLD_ALLOWANCE):
    """(line, bad triangle mask) of the first thing a body cannot be on the corrected surface: a fold, then a
    stretch (None, None for a plausible one)."""
    folds = fold_problems(before, after, faces, allowance)
    if folds:
        old = np.cross(before[faces[:, 1]] - before[faces[:, 0]], before[faces[:, 2]] - before[faces[:, 0]])
        new = np.cross(after[faces[:, 1]] - after[faces[:, 0]], after[faces[:, 2]] - after[faces[:, 0]])
        return "would fold the mesh (" + folds[0] + ")", np.einsum("ij,ij->i", old, new) <= 0.0
    return stretch_problem(before, after, faces)


def blame(deformation, theta, keys, faces, bad):
    """The key of ``keys`` whose part of the correction moves the vertices of the ``bad`` triangles most."""
    vertices = np.unique(faces[bad])
    moved = [
        np.linalg.norm(theta[PARAMETERS.index(key)] * deformation.basis[PARAMETERS.index(key), vertices], axis=1).sum()
        for key in keys
    ]
    return keys[int(np.argmax(moved))]


def abduction_for(depth, where, height, shoulder_height):
    """The angle (radians) the arms are raised by to clear an intrusion ``depth`` m deep at ``where`` (fraction of
    He): the lateral move at that height's distance below the shoulder."""
    below = max(shoulder_height - where * height, 0.05)
    return float(np.arctan((depth + ABDUCTION_MARGIN) / below))


def describe_reach(key, request, start, reach):
    """Words for a refused measurement: what was asked, what the bodies give, how far the body skin goes."""
    unit = "cm"
    if reach is None:
        return f"{key} {request:.1f} {unit} ({start:.1f} {unit} from the bodies)"
    short = abs(request - reach)
    return (
        f"{key} {request:.1f} {unit} is {request - start:+.1f} {unit} from the bodies' {start:.1f} {unit}; "
        f"the body skin reaches {reach:.1f} {unit} ({short:.1f} {unit} short)"
    )


def bisect_reach(attempt, key, request, start, steps=REACH_STEPS):
    """The value of ``key`` nearest to ``request[key]`` on the way from ``start`` (what the bodies give) for which
    ``attempt(request)`` makes a plausible skin (True), the rest of the request kept; None when not even
    ``start`` does."""
    trial = dict(request)
    trial[key] = start
    if not attempt(trial):
        return None
    good, bad = 0.0, 1.0
    for _ in range(steps):
        middle = 0.5 * (good + bad)
        trial[key] = start + middle * (request[key] - start)
        if attempt(trial):
            good = middle
        else:
            bad = middle
    return start + good * (request[key] - start)


def intrusion_blame(correction, keys, where, fractions):
    """The measurement an arm's intrusion at ``where`` (fraction of He) is blamed on: the shoulders when the
    correction narrowed them, else the girth whose section is nearest."""
    theta = correction.theta
    if "Sh" in keys and theta[PARAMETERS.index("Sh")] < 0.0:
        return "Sh"
    girths = [key for key in ("Br", "Wa", "Hi") if key in keys]
    return min(girths, key=lambda key: abs(fractions[key] - where)) if girths else keys[0]
