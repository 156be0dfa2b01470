"""Exact mode on the skin: the skin, not only the pieces, measures what was asked.

The blend adds a little where neighbours meet, so a skin over pieces that meet the request measures a few
millimetres to centimetres more in its girths. The loop asks the pieces for less by what the skin adds: with
R the request and S(B) the skin's measurements of pieces B, it refines the pieces (exact mode's own refinement,
``core.synthesis.refine``) to targets T_k, measures their skin on the surface itself (``core.skin.measure``),
and sets T_{k+1} = T_k + R - S(B_k) until every measurement is within SKIN_TOLERANCE_CM. What the skin adds
changes slowly with the pieces, so two or three rounds do; the skin is then meshed once and measured on its
mesh, which agrees with the surface's measurements to a fraction of a millimetre (one more round if not).
The pieces' own m_T is returned beside the skin's.

The six extra measurements (neck, upper arm, thigh, calf, crotch height, arm length) join the same loop when
asked: the pieces meet offset targets of all eleven through the extra measurements' own refinement
(``core.synthesis.extra_refine.meet_extra``, which re-meets the five after every round of its own), and the
skin is measured on its mesh by the body-mesh measurer (``core.measure.body.measure_body_mesh``: a skin is
measured as any scan is, by the same public definitions), every round, since those definitions have no
surface-only form here.
"""

from dataclasses import dataclass

import numpy as np

from ..errors import ElliMannError
from ..mannequin.joints import anchor_indices, follow_pieces
from ..measure.extra import mannequin_extra_measurements
from ..measure.tailor import as_dict
from ..measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ..synthesis.extra_refine import ExtraRequestError, extra_request_problems, meet_extra
from ..synthesis.misses import SKIN_MISS_CM
from ..synthesis.refine import refine
from .measure import body_measurements, field_measurements, mesh_measurements
from .surface import build_skin

SKIN_TOLERANCE_CM = 0.03  # the loop's aim on the surface: 0.3 mm (the promise on the mesh is 1 mm)
MESH_TOLERANCE_CM = SKIN_MISS_CM  # what the skin's mesh must measure within
EXTRA_AIM_CM = 0.05  # the loop's aim on the mesh with extra measurements: half the promise, a margin for the last
MAX_ROUNDS = 8
EXTRA_MAX_ROUNDS = 10
SLOPE_RANGE = (0.3, 8.0)  # the skin's response to its pieces' target, per measurement, as the secant may find it
SECANT_MIN_STEP_CM = 0.01  # a target moved less than this tells no slope (the mesh's own noise is near it)
MAX_STEP = 0.15  # no target moves by more than this share of the request in one round


@dataclass
class ExactSkin:
    """The pieces (``mannequin``, their m_T ``pieces_measured``) whose ``skin`` measures ``skin_measured``
    ({key: cm}, on its mesh) for the ``request`` (the five, and the extra measurements asked, if any: those are
    in ``pieces_measured`` and ``skin_measured`` too); ``rounds`` of the loop; ``converged``: within
    MESH_TOLERANCE_CM."""

    mannequin: object
    skin: object
    request: dict
    skin_measured: dict
    pieces_measured: dict
    rounds: int
    converged: bool

    def misses(self):
        """[(key, skin cm, requested cm)] of the measurements the skin missed by more than MESH_TOLERANCE_CM."""
        return [
            (key, self.skin_measured[key], self.request[key])
            for key in self.request
            if abs(self.skin_measured[key] - self.request[key]) > MESH_TOLERANCE_CM
        ]


def exact_skin(mannequin, settings, request=None, extra=None, max_rounds=None):
    """Pieces near ``mannequin`` whose skin at ``settings`` measures ``request`` ({He..Hi: cm}; default the
    mannequin's own targets, which exact mode's pieces already meet) and ``extra`` ({key: cm} of
    EXTRA_MEASUREMENTS, any of the six): an ExactSkin. ExtraRequestError (one line) for extra measurements out of
    their limits or contradicting the five; ElliMannError if the skin's mesh cannot be measured for one asked."""
    request = {key: float(value) for key, value in (request or mannequin.measurements or {}).items()}
    missing = [key for key in MEASUREMENTS if key not in request]
    if missing:
        raise ElliMannError(f"skin: exact mode needs the requested {', '.join(missing)} (cm); the mannequin has none")
    request = {key: request[key] for key in MEASUREMENTS}
    if extra:
        extra = {key: float(value) for key, value in extra.items()}
        problems = extra_request_problems(request, extra)
        if problems:
            raise ExtraRequestError(problems[0])
        extra = {key: extra[key] for key in EXTRA_MEASUREMENTS if key in extra}
        return _exact_with_extra(mannequin, settings, request, extra, max_rounds or EXTRA_MAX_ROUNDS)
    return _exact_five(mannequin, settings, request, max_rounds or MAX_ROUNDS)


def _exact_five(mannequin, settings, request, max_rounds):
    """exact_skin for the five alone: the loop measures the surface (no mesh) until the last round. Where the
    mesh measures otherwise than the surface (a coarse voxel's facets cut inside a slim body's curves: 1.6 mm
    of Wa at 10 mm), the surface is aimed that much beyond the request from then on, so that the mesh meets it
    (aiming the surface at the request itself undid each mesh round's correction in the next)."""
    wanted = np.array([request[key] for key in MEASUREMENTS])
    targets, aim = wanted.copy(), wanted.copy()
    current, rounds = mannequin, 0
    while True:
        on_surface = field_measurements(current, settings)
        on_surface = np.array([on_surface[key] for key in MEASUREMENTS])
        error = aim - on_surface
        if np.all(np.abs(error) <= SKIN_TOLERANCE_CM) or rounds >= max_rounds:
            skin = build_skin(current, settings)
            on_mesh = mesh_measurements(skin)
            mesh_error = wanted - np.array([on_mesh[key] for key in MEASUREMENTS])
            if np.all(np.abs(mesh_error) <= MESH_TOLERANCE_CM) or rounds >= max_rounds:
                break
            aim = wanted + on_surface - (wanted - mesh_error)  # the surface's aim: the request and what the mesh lacks
            error = aim - on_surface
        targets = targets + error
        current = _refined(mannequin, targets)
        rounds += 1
    pieces = as_dict(np.asarray([current.measure()[key] for key in MEASUREMENTS]))
    converged = bool(np.all(np.abs(mesh_error) <= MESH_TOLERANCE_CM))
    return ExactSkin(current, skin, request, on_mesh, pieces, rounds, converged)


def _exact_with_extra(mannequin, settings, request, extra, max_rounds):
    """exact_skin with extra measurements: every round the pieces meet offset targets of the five and the extra
    ones (meet_extra, from the last round's pieces: small steps deform them smoothly, where starting over let
    meet_extra's own rounds end elsewhere and the skin's upper arm jumped by millimetres), their skin is meshed and
    measured on the mesh, and each target moves by its error over the skin's response to it (a secant per
    measurement: the skin's neck, say, grows faster than its pieces'). A round further from the request than the
    best one (or whose skin cannot be made or measured) is undone: the next goes half as far from the best. The
    best is kept."""
    keys = list(request) + list(extra)
    count = len(MEASUREMENTS)
    wanted = np.array([request[key] for key in MEASUREMENTS] + [extra[key] for key in extra])
    targets, slope, best = wanted.copy(), np.ones(len(keys)), None
    start = mannequin
    for rounds in range(max_rounds + 1):
        five, more = dict(zip(MEASUREMENTS, targets[:count])), dict(zip(extra, targets[count:]))
        pieces, _, _ = meet_extra(start.copy(measurements=five), more)
        try:
            skin = build_skin(pieces, settings)
            on_mesh = _skin_all(skin, list(extra))
        except ElliMannError:  # a skin that cannot be made (SkinError) or measured: undone, unless the first round's
            if best is None:
                raise
            skin = None
        if skin is not None:
            measured = np.array([on_mesh[key] for key in keys])
            worst = float(np.abs(wanted - measured).max())
        if best is not None and (skin is None or worst >= best.worst):  # undone: back towards the best round
            targets, start = best.targets + 0.5 * (targets - best.targets), best.pieces
            continue
        if best is not None:
            moved = targets - best.targets
            with np.errstate(divide="ignore", invalid="ignore"):
                secant = (measured - best.measured) / moved
            known = np.abs(moved) > SECANT_MIN_STEP_CM
            slope[known] = np.clip(secant[known], *SLOPE_RANGE)
        best = _Round(worst, targets, measured, pieces, skin, on_mesh, rounds)
        if worst <= EXTRA_AIM_CM:
            break
        targets = targets + np.clip((wanted - measured) / slope, -MAX_STEP * wanted, MAX_STEP * wanted)
        start = pieces
    pieces_measured = {**best.pieces.measure(), **mannequin_extra_measurements(best.pieces)}
    pieces_measured = {key: float(pieces_measured[key]) for key in keys}
    converged = best.worst <= MESH_TOLERANCE_CM
    return ExactSkin(
        best.pieces, best.skin, {**request, **extra}, best.on_mesh, pieces_measured, best.rounds, converged
    )


@dataclass
class _Round:
    """A round of the loop with extra measurements: its largest error (cm), targets, what the skin measured (both
    in the loop's order), the pieces, their skin and its measurements {key: cm}, the round's number."""

    worst: float
    targets: np.ndarray
    measured: np.ndarray
    pieces: object
    skin: object
    on_mesh: dict
    rounds: int


def _skin_all(skin, extra_keys):
    """{the five and ``extra_keys``: cm} of a skin's mesh: the five by m_T's definitions (the arms left out by the
    pieces they follow), the extra ones by the body-mesh measurer's."""
    measured = mesh_measurements(skin)
    body = body_measurements(skin)
    lost = [key for key in extra_keys if key not in body.values]
    if lost:
        why = next((line for line in body.problems if any(key in line for key in lost)), "; ".join(body.problems))
        raise ElliMannError(f"skin: {', '.join(lost)} cannot be measured on the skin's mesh ({why})")
    return {**measured, **{key: body.values[key] for key in extra_keys}}


def _refined(mannequin, targets):
    """``mannequin`` deformed by exact mode's refinement until its m_T is ``targets`` (5,) cm, joints moved along."""
    arrays = (mannequin.rotation[None], mannequin.center[None], mannequin.semi_axes[None])
    result = refine(mannequin.topology, *arrays, np.asarray(targets)[None], fractions=mannequin.section_fractions)
    joints = mannequin.joints
    if joints is not None:
        after = (arrays[0], result.center, result.semi_axes)
        joints = follow_pieces(joints[None], anchor_indices(mannequin.topology), arrays, after)[0]
    return mannequin.copy(center=result.center[0], semi_axes=result.semi_axes[0], joints=joints)
