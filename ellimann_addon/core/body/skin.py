"""The body skin: the set's bodies interpolated for a request (core.body.model) and corrected on the mesh until
it measures the request (core.body.correct), bound to the 24 joints with the bodies' own bone weights.

``BodySkin`` answers as ``core.skin.surface.Skin`` does where a body can: ``vertices``, ``faces``, ``bones()``,
``posed(pose)``, ``measure()``, ``volume``; it has no pieces (``pieces``/``weights``/``following`` belong to a
skin over pieces), its ``joints`` are its own (the bodies' joints carried through the blend and the correction).
"""

import pathlib
import time
from dataclasses import dataclass, field

import numpy as np

from ..geometry.mesh import volume
from ..measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ..pose.kinematics import bone_matrices
from ..synthesis.bodies import load_set_bodies
from .correct import LIMITS, PROMISE_CM, BodySkinError, correct
from .deform import PARAMETERS, Deformation
from .mesh_checks import FOLD_ALLOWANCE, fold_problems
from .model import IdwBodyModel
from .tape import Tape


@dataclass
class BodySkin:
    """A body skin: ``vertices`` (V, 3) m and ``faces`` (F, 3) of the set's topology, its ``joints`` (24, 3),
    bone weights (``bones()``), the ``request`` ({key: cm}) and what the skin measures (``measured``, by the
    body-mesh measurer), the body model's ``weights`` of the set's bodies, the correction's ``rounds`` and
    ``seconds``; ``pieces_measured``: the pieces' own m_T beside it, when the caller has pieces."""

    vertices: np.ndarray
    faces: np.ndarray
    joints: np.ndarray
    bodies: object
    request: dict
    measured: dict
    weights: np.ndarray = None
    rounds: int = 0
    seconds: float = 0.0
    pieces_measured: dict = field(default_factory=dict)

    def bones(self):
        """(joint indices (V, 4), weights (V, 4)) on the SMPL joints: the body model's own, summed per joint."""
        return self.bodies.joint_index, self.bodies.joint_weight

    def posed(self, pose):
        """The vertices (V, 3) in ``pose`` (core.pose.kinematics.Pose): linear-blend skinning on :meth:`bones`
        about this skin's own joints."""
        matrices = bone_matrices(self.joints, pose)[:, :3, :]
        index, weight = self.bones()
        homogeneous = np.c_[self.vertices, np.ones(len(self.vertices))]
        moved = np.einsum("vkij,vj->vki", matrices[index], homogeneous)
        return np.einsum("vk,vki->vi", weight, moved)

    @property
    def arms(self):
        return self.bodies.arms

    def measure(self, fractions=None, neck_tilt=None):
        """The skin measured as any body mesh (core.measure.body), its arms known from the labels: a
        BodyMeasurement at ``fractions`` (default the set's)."""
        return Tape(self.faces, self.arms, fractions or self.bodies.fractions).full(self.vertices, neck_tilt)

    @property
    def volume(self):
        return volume(self.vertices, self.faces)

    def misses(self):
        """[(key, measured cm, requested cm)] beyond the promise (1 mm)."""
        return [
            (key, self.measured[key], value)
            for key, value in self.request.items()
            if abs(self.measured[key] - value) > PROMISE_CM
        ]


def largest_change(found, request):
    """What the correction changed most (relative to its limit), in words: "scaling the Wa section by 0.82 for
    Wa 63.0 cm (the bodies give 76.8 cm)"."""
    keys = [key for key in PARAMETERS if key in request]
    share = [abs(found.theta[PARAMETERS.index(key)]) / LIMITS[key] for key in keys]
    key = keys[int(np.argmax(share))]
    theta = found.theta[PARAMETERS.index(key)]
    how = f"moving each arm {abs(theta) * 100:.1f} cm" if key == "Sh" else f"scaling by {1.0 + theta:.2f}"
    start = found.start[key]
    return f"{key} {request[key]:.1f} cm is {request[key] - start:+.1f} cm from the bodies' {start:.1f} cm: {how}"


class BodySkinMaker:
    """Makes body skins from a set's ``bodies`` (SetBodies) with a body ``model`` (default IDW over them, the
    set's ``ranges`` for its metric). The tape and the topology's checks are made once."""

    def __init__(self, bodies, model=None, ranges=None):
        self.bodies = bodies
        self.model = model or IdwBodyModel(bodies, ranges)
        self.tape = Tape(bodies.faces, bodies.arms, bodies.fractions)

    def interpolated(self, request):
        """(vertices, joints) of the body model alone (no correction)."""
        return self.model.body(request)

    def make(self, request, extra=None, check=True):
        """The BodySkin of ``request`` ({He..Hi: cm}) and ``extra`` ({key: cm} of any of the six extras).
        BodySkinError (one line) for a request beyond the bodies or a mesh that would fold."""
        started = time.perf_counter()
        asked = {key: float(request[key]) for key in MEASUREMENTS}
        asked |= {key: float(value) for key, value in (extra or {}).items()}
        unknown = [key for key in asked if key not in MEASUREMENTS + EXTRA_MEASUREMENTS]
        if unknown:
            raise BodySkinError(f"body skin: {', '.join(unknown)} is no measurement ElliMann takes")
        vertices, joints = self.model.body(asked)
        crotch = None
        extras = [key for key in asked if key in EXTRA_MEASUREMENTS]
        tilt = None
        if extras:
            first = self.tape.full(vertices)
            tilt = first.neck_tilt if np.isfinite(first.neck_tilt) else None
            crotch = first.values.get("crotch_height")
            crotch = None if crotch is None else crotch / 100.0
        deformation = Deformation(vertices, joints, self.bodies.dense_weights, self.bodies.fractions, crotch)
        found = correct(deformation, self.tape, asked, tilt)
        corrected, moved_joints = deformation.apply(found.theta)
        measured = found.measured
        if extras:  # the whole measurer, the neck's tilt searched as on any scan
            full = self.tape.full(corrected).values
            measured = {key: full.get(key, np.nan) for key in asked}
            if any(abs(measured[key] - asked[key]) > PROMISE_CM for key in asked):
                found = correct(deformation, self.tape, asked, None)
                corrected, moved_joints = deformation.apply(found.theta)
                measured = found.measured
        if check:
            problems = fold_problems(vertices, corrected, self.bodies.faces, FOLD_ALLOWANCE)
            if problems:
                raise BodySkinError(f"body skin: {largest_change(found, asked)} would fold the mesh ({problems[0]})")
        weights = getattr(self.model, "weights", None)
        return BodySkin(
            corrected,
            self.bodies.faces,
            moved_joints,
            self.bodies,
            asked,
            measured,
            weights(asked) if weights else None,
            found.rounds,
            time.perf_counter() - started,
        )


def body_skin_maker(reference):
    """A BodySkinMaker for a loaded ReferenceSet whose folder holds bodies (None without): the set's ranges
    for the model. ``reference.sources`` locate the folder."""
    if not getattr(reference, "sources", None):
        return None
    bodies = load_set_bodies(pathlib.Path(reference.sources[0]).parent)
    return None if bodies is None else BodySkinMaker(bodies, ranges=reference.ranges)
