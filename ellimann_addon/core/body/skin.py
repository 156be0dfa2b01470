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

from ..constants import MEASUREMENTS
from ..geometry.mesh import volume
from ..measure.extra import EXTRA_MEASUREMENTS
from ..measure.further import FURTHER_MEASUREMENTS
from ..pose.kinematics import bone_matrices
from ..synthesis.bodies import load_set_bodies
from ..synthesis.body_space import load_set_body_space
from .correct import LIMITS, PROMISE_CM, BodySkinError, correct
from .deform import PARAMETERS, Deformation
from .mesh_checks import FOLD_ALLOWANCE, fold_problems
from .model import IdwBodyModel
from .ridge import RidgeBodyModel
from .tape import Tape

BODY_MODELS = (None, "ridge", "idw")  # body_skin_maker's choices (None: the best the set has)


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
    informed: dict = field(default_factory=dict)  # measurements the body model took that the correction did not meet

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
    set's ``ranges`` for its metric; core.body.ridge.RidgeBodyModel over a set's body space). The tape and the
    topology's checks are made once."""

    def __init__(self, bodies, model=None, ranges=None):
        self.bodies = bodies
        self.model = model or IdwBodyModel(bodies, ranges)
        self.tape = Tape(bodies.faces, bodies.arms, bodies.fractions)

    def interpolated(self, request):
        """(vertices, joints) of the body model alone (no correction)."""
        return self.model.body(request)

    def make(self, request, extra=None, check=True, shape=None, tolerances=None):
        """The BodySkin of ``request`` ({He..Hi: cm}) and ``extra`` ({key: cm} of any of the six extras), both met
        by the correction; ``shape`` ({key: cm} of any measurement the model takes, core.measure.further's too):
        inputs of the body model only (its ``informed``); ``tolerances`` ({key: cm} or "exact"): the tape's error
        the model weighs each input by (a model that takes them: core.body.ridge). BodySkinError (one line) for a
        request beyond the bodies or a mesh that would fold."""
        started = time.perf_counter()
        asked = {key: float(request[key]) for key in MEASUREMENTS}
        asked |= {key: float(value) for key, value in (extra or {}).items()}
        informed = {key: float(value) for key, value in (shape or {}).items() if key not in asked}
        unknown = [key for key in asked if key not in MEASUREMENTS + EXTRA_MEASUREMENTS]
        unknown += [key for key in informed if key not in MEASUREMENTS + EXTRA_MEASUREMENTS + FURTHER_MEASUREMENTS]
        if unknown:
            raise BodySkinError(f"body skin: {', '.join(unknown)} is no measurement ElliMann takes")
        inputs = asked | informed
        if tolerances is None:
            vertices, joints = self.model.body(inputs)
        else:
            vertices, joints = self.model.body(inputs, tolerances)
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
            weights(inputs) if weights else None,
            found.rounds,
            time.perf_counter() - started,
            informed=informed,
        )


def body_skin_maker(reference, model=None, tolerances=None):
    """A BodySkinMaker for a loaded ReferenceSet whose folder holds bodies (None without). ``model``: None (the
    best the set has: ridge regression over its body space when it has one, else IDW over its bodies), "ridge" or
    "idw" (the set's ranges for its metric); ``tolerances``: the ridge's default (core.body.ridge). BodySkinError
    for "ridge" on a set without a body space. ``reference.sources`` locate the folder."""
    if model not in BODY_MODELS:
        raise BodySkinError(f"body model: {model!r} is not one of {', '.join(str(m) for m in BODY_MODELS)}")
    if not getattr(reference, "sources", None):
        return None
    folder = pathlib.Path(reference.sources[0]).parent
    bodies = load_set_bodies(folder)
    if bodies is None:
        return None
    space = None if model == "idw" else load_set_body_space(folder)
    if space is None and model == "ridge":
        raise BodySkinError(f"body model: the set in {folder} has no body space (body_space.npz): use 'idw'")
    if space is None:
        return BodySkinMaker(bodies, ranges=reference.ranges)
    return BodySkinMaker(bodies, RidgeBodyModel(space, tolerances))
