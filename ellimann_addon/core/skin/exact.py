"""Exact mode on the skin: the skin, not only the pieces, measures what was asked.

The blend adds a little where neighbours meet, so a skin over pieces that meet the request measures a few
millimetres to centimetres more in its girths. The loop asks the pieces for less by what the skin adds: with
R the request and S(B) the skin's measurements of pieces B, it refines the pieces (exact mode's own refinement,
``core.synthesis.refine``) to targets T_k, measures their skin on the surface itself (``core.skin.measure``),
and sets T_{k+1} = T_k + R - S(B_k) until every measurement is within SKIN_TOLERANCE_CM. What the skin adds
changes slowly with the pieces, so two or three rounds do; the skin is then meshed once and measured on its
mesh, which agrees with the surface's measurements to a fraction of a millimetre (one more round if not).
The pieces' own m_T is returned beside the skin's.
"""

from dataclasses import dataclass

import numpy as np

from ..constants import MEASUREMENTS
from ..errors import ElliMannError
from ..mannequin.joints import anchor_indices, follow_pieces
from ..measure.tailor import as_dict
from ..synthesis.refine import refine
from .measure import field_measurements, mesh_measurements
from .surface import build_skin

SKIN_TOLERANCE_CM = 0.03  # the loop's aim on the surface: 0.3 mm (the promise on the mesh is 1 mm)
MESH_TOLERANCE_CM = 0.1  # what the skin's mesh must measure within
MAX_ROUNDS = 8


@dataclass
class ExactSkin:
    """The pieces (``mannequin``, their m_T ``pieces_measured``) whose ``skin`` measures ``skin_measured``
    ({key: cm}, on its mesh) for the ``request``; ``rounds`` of the loop; ``converged``: within MESH_TOLERANCE_CM."""

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
            for key in MEASUREMENTS
            if abs(self.skin_measured[key] - self.request[key]) > MESH_TOLERANCE_CM
        ]


def exact_skin(mannequin, settings, request=None, max_rounds=MAX_ROUNDS):
    """Pieces near ``mannequin`` whose skin at ``settings`` measures ``request`` ({He..Hi: cm}; default the
    mannequin's own targets, which exact mode's pieces already meet): an ExactSkin."""
    request = {key: float(value) for key, value in (request or mannequin.measurements or {}).items()}
    missing = [key for key in MEASUREMENTS if key not in request]
    if missing:
        raise ElliMannError(f"skin: exact mode needs the requested {', '.join(missing)} (cm); the mannequin has none")
    wanted = np.array([request[key] for key in MEASUREMENTS])
    targets = wanted.copy()
    current, rounds = mannequin, 0
    while True:
        measured = field_measurements(current, settings)
        error = wanted - np.array([measured[key] for key in MEASUREMENTS])
        if np.all(np.abs(error) <= SKIN_TOLERANCE_CM) or rounds >= max_rounds:
            skin = build_skin(current, settings)
            on_mesh = mesh_measurements(skin)
            error = wanted - np.array([on_mesh[key] for key in MEASUREMENTS])
            if np.all(np.abs(error) <= MESH_TOLERANCE_CM) or rounds >= max_rounds:
                break
        targets = targets + error
        current = _refined(mannequin, targets)
        rounds += 1
    pieces = as_dict(np.asarray([current.measure()[key] for key in MEASUREMENTS]))
    converged = bool(np.all(np.abs(error) <= MESH_TOLERANCE_CM))
    return ExactSkin(current, skin, request, on_mesh, pieces, rounds, converged)


def _refined(mannequin, targets):
    """``mannequin`` deformed by exact mode's refinement until its m_T is ``targets`` (5,) cm, joints moved along."""
    arrays = (mannequin.rotation[None], mannequin.center[None], mannequin.semi_axes[None])
    result = refine(mannequin.topology, *arrays, np.asarray(targets)[None], fractions=mannequin.section_fractions)
    joints = mannequin.joints
    if joints is not None:
        after = (arrays[0], result.center, result.semi_axes)
        joints = follow_pieces(joints[None], anchor_indices(mannequin.topology), arrays, after)[0]
    return mannequin.copy(center=result.center[0], semi_axes=result.semi_axes[0], joints=joints)
