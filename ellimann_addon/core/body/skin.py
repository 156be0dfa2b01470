"""The body skin: the set's bodies interpolated for a request (core.body.model) and corrected on the mesh until
it measures the request (core.body.correct), judged plausible or refused with how far it reaches
(core.body.plausible), bound to the 24 joints with the bodies' own bone weights, the hips' re-drawn
(core.body.hips).

``BodySkin`` answers as ``core.skin.surface.Skin`` does where a body can: ``vertices``, ``faces``, ``bones()``,
``posed(pose)``, ``measure()``, ``volume``; it has no pieces (``pieces``/``weights``/``following`` belong to a
skin over pieces), its ``joints`` are its own (the bodies' joints carried through the blend and the correction).
"""

import pathlib
import time
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..geometry.mesh import volume
from ..mannequin.skeleton import JOINT_INDEX
from ..measure.further import FURTHER_MEASUREMENTS
from ..measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ..synthesis.bodies import load_set_bodies
from ..synthesis.body_space import load_set_body_space
from .correct import AIM_CM, PROMISE_CM, BodySkinError, correct
from .deform import PARAMETERS, Deformation, abducted, smoothed
from .extra_tape import ExtraTape, Marks, leg_masks
from .hips import balanced_bones, skinned
from .mesh_checks import arm_intrusion
from .model import IdwBodyModel
from .plausible import (
    INTRUSION_TOLERANCE,
    MAX_ABDUCTION,
    abduction_for,
    bisect_reach,
    blame,
    describe_reach,
    intrusion_blame,
    proportion_problem,
    surface_problem,
)
from .ridge import RidgeBodyModel, resolve_tolerances
from .tape import Tape

BODY_MODELS = (None, "ridge", "idw")  # body_skin_maker's choices (None: the best the set has)


@dataclass
class BodySkin:
    """A body skin: ``vertices`` (V, 3) m and ``faces`` (F, 3) of the set's topology, its ``joints`` (24, 3),
    bone weights (``bones()``), the ``request`` ({key: cm}) and what the skin measures (``measured``, by the
    body-mesh measurer), the body model's ``weights`` of the set's bodies, the correction's ``rounds`` and
    ``seconds``; ``pieces_measured``: the pieces' own m_T beside it, when the caller has pieces; ``abduction``:
    how far (radians) its arms were raised sideways from the bodies' A-pose to clear its trunk."""

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
    abduction: float = 0.0
    mannequin: object = None  # the pieces it goes with (a job's: core.job.make), their joints this skin's
    settings: object = None  # how it was asked (core.mannequin.skin_record.SkinSettings, kind "body")
    informed: dict = field(default_factory=dict)  # measurements the body model took that the correction did not meet

    def record(self):
        """The ``skin`` section of the file of the pieces it goes with: how to make it again (the request)."""
        return self.settings.to_dict(self.request)

    @cached_property
    def _balanced(self):
        return balanced_bones(self.vertices, self.faces, self.joints, self.bodies.dense_weights)

    def bones(self):
        """(joint indices (V, 4), weights (V, 4)) on the SMPL joints: the body model's own, summed per joint, with
        the pelvis's and the thighs' shares re-drawn across the hips' tilted planes (core.body.hips): plain
        linear-blend skinning that keeps the volume when sitting."""
        return self._balanced[0]

    @property
    def hip_planes(self):
        """(drop, half-width, tilt) of the hips' planes (core.body.hips) at which the skin keeps its volume in
        sit: shares of the thigh's length, radians about world X."""
        return self._balanced[1]

    def posed(self, pose):
        """The vertices (V, 3) in ``pose`` (core.pose.kinematics.Pose): linear-blend skinning on :meth:`bones`
        about this skin's own joints."""
        return skinned(self.vertices, self.joints, *self.bones(), pose)

    @property
    def arms(self):
        return self.bodies.arms

    def measure(self, fractions=None, neck_tilt=None):
        """The skin measured as ``measure`` reads any body mesh (core.measure.body), its arms known from the
        labels: a BodyMeasurement at ``fractions`` (default the set's), the neck square to ``neck_tilt`` (radians;
        default the tilt a tape settles at, as on the scan a twin is made for)."""
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


FINAL_PASSES = 3  # whole readings of a skin with extras (each but the last followed by a loop aimed anew)


@dataclass
class Attempt:
    """One try at a request: the corrected ``vertices`` and ``joints``, the ``correction`` (core.body.correct)
    on ``deformation``, the arms' ``abduction`` (radians), and the first ``problem`` (a line) with the measurement
    it is blamed on (``blamed``), None for a plausible body skin."""

    vertices: np.ndarray
    joints: np.ndarray
    correction: object
    deformation: object
    abduction: float = 0.0
    problem: str = None
    blamed: str = None


class BodySkinMaker:
    """Makes body skins from a set's ``bodies`` (SetBodies) with a body ``model`` (default IDW over them, the
    set's ``ranges`` for its metric; core.body.ridge.RidgeBodyModel over a set's body space). The tape and the
    topology's checks are made once."""

    def __init__(self, bodies, model=None, ranges=None):
        self.bodies = bodies
        self.model = model or IdwBodyModel(bodies, ranges)
        self.tape = Tape(bodies.faces, bodies.arms, bodies.fractions)
        legs = leg_masks(bodies.region, bodies.region_names)
        self.extra_tape = ExtraTape(bodies.faces, bodies.arms, legs, bodies.fractions)
        self.weights = smoothed(bodies.dense_weights, bodies.faces)

    def interpolated(self, request, tolerances=None):
        """(vertices, joints) of the body model alone (no correction) for ``request`` ({key: cm}: any inputs the
        model takes), its inputs weighed by ``tolerances`` (a model that takes them: core.body.ridge)."""
        return self.model.body(request) if tolerances is None else self.model.body(request, tolerances)

    def make(self, request, extra=None, check=True, shape=None, tolerances=None):
        """The BodySkin of ``request`` ({He..Hi: cm}) and ``extra`` ({key: cm} of any of the six extras), both met
        by the correction; ``shape`` ({key: cm} of any measurement the model takes, core.measure.further's too):
        inputs of the body model only (its ``informed``); ``tolerances`` ({key: cm} or "exact"): the tape's error
        the model weighs each input by (a model that takes them: core.body.ridge). BodySkinError (one line) for a
        request no plausible body skin meets (core.body.plausible), naming the measurement, how far the body skin
        reaches and why not further; ``check=False``: no plausibility checks."""
        started = time.perf_counter()
        asked = {key: float(request[key]) for key in MEASUREMENTS}
        asked |= {key: float(value) for key, value in (extra or {}).items()}
        informed = {key: float(value) for key, value in (shape or {}).items() if key not in asked}
        unknown = [key for key in asked if key not in MEASUREMENTS + EXTRA_MEASUREMENTS]
        unknown += [key for key in informed if key not in MEASUREMENTS + EXTRA_MEASUREMENTS + FURTHER_MEASUREMENTS]
        if unknown:
            raise BodySkinError(f"body skin: {', '.join(unknown)} is no measurement ElliMann takes")
        self._check_model_asks(informed, tolerances)
        if check:
            problem, _ = proportion_problem(asked, self.bodies.fractions)
            if problem:
                raise BodySkinError(f"body skin: {problem}; no body has these proportions")
        inputs = asked | informed
        attempt = self.attempt(asked, check, informed, tolerances)
        if attempt.problem:
            raise BodySkinError(self.refusal(asked, attempt, informed, tolerances))
        found = attempt.correction
        measured = found.measured
        return BodySkin(
            attempt.vertices,
            self.bodies.faces,
            attempt.joints,
            self.bodies,
            asked,
            measured,
            self.model.weights(inputs, tolerances) if tolerances is not None else self.model.weights(inputs),
            found.rounds,
            time.perf_counter() - started,
            abduction=attempt.abduction,
            informed=informed,
        )

    def _check_model_asks(self, informed, tolerances):
        """BodySkinError (one line) for what the body model would not use: a shape or tolerances without a body
        space (the five bodies' IDW reads the five alone), a tolerance that names no measurement or is no cm."""
        if not isinstance(self.model, RidgeBodyModel):
            if informed or tolerances is not None:
                what = "shape measurements" if informed else "tolerances"
                raise BodySkinError(f"body skin: {what} need the set's body space (body_space.npz); this set has none")
            return
        if isinstance(tolerances, dict):
            unknown = [key for key in tolerances if key not in MEASUREMENTS + EXTRA_MEASUREMENTS + FURTHER_MEASUREMENTS]
            if unknown:
                raise BodySkinError(f"body skin: tolerances: {', '.join(unknown)} is no measurement ElliMann takes")
        try:
            resolve_tolerances(tolerances, ())
        except ValueError as error:
            raise BodySkinError(f"body skin: {error}") from None

    def attempt(self, asked, check=True, informed=None, tolerances=None):
        """An Attempt at ``asked`` ({key: cm}): the body model's body (``informed`` its inputs too, weighed by
        ``tolerances``), its arms raised as far as they must be to clear the trunk, corrected; its first problem
        (core.body.plausible) when ``check``."""
        vertices, joints = self.interpolated(asked | (informed or {}), tolerances)
        faces, arms = self.bodies.faces, self.bodies.arms
        angle = 0.0
        while True:
            rest, rest_joints = abducted(vertices, joints, self.weights, angle) if angle else (vertices, joints)
            found, deformation = self.corrected(asked, rest, rest_joints)
            corrected, moved = deformation.apply(found.theta)
            attempt = Attempt(corrected, moved, found, deformation, angle)
            keys = [key for key in PARAMETERS if key in asked]
            if found.beyond or not found.converged:
                worst = found.beyond or max(keys, key=lambda k: abs(found.measured[k] - asked[k]))
                attempt.problem, attempt.blamed = "the correction would leave any body's proportions", worst
                return attempt
            if not check:
                return attempt
            depth, where = arm_intrusion(corrected, faces, arms)
            if depth <= INTRUSION_TOLERANCE:
                break
            shoulder = float(np.mean(rest_joints[[JOINT_INDEX["L_Shoulder"], JOINT_INDEX["R_Shoulder"]], 2]))
            more = abduction_for(depth, where, np.ptp(rest[:, 2]), shoulder - rest[:, 2].min())
            if angle >= MAX_ABDUCTION:
                attempt.problem = (
                    f"the arms would cut {depth * 100:.1f} cm into the trunk at {where:.2f} He, raised by "
                    f"{np.degrees(angle):.0f} degrees (at most)"
                )
                attempt.blamed = intrusion_blame(found, keys, where, self.bodies.fractions)
                return attempt
            angle = min(angle + more, MAX_ABDUCTION)
        attempt.problem, bad = surface_problem(rest, corrected, faces)
        if attempt.problem:
            attempt.blamed = blame(deformation, found.theta, keys, faces, bad)
        return attempt

    def corrected(self, asked, rest, joints):
        """(Correction, Deformation) of the body ``rest`` with ``joints`` to ``asked``: the five by the tape, the
        extras by the extras' tape in windows about their last extremes, the neck square to the tilt the last whole
        reading settled at (held through a loop: a tilt searched anew each round jumps between nearby bodies); then
        every band searched whole on the corrected body, its neck at the tilt a tape settles at, as ``measure``
        reads any body mesh (the final reading); when that differs from the loop's by more than the aim, the loop
        again from there, aimed by the difference."""
        keys = [key for key in PARAMETERS if key in asked]
        extras = [key for key in keys if key in EXTRA_MEASUREMENTS]
        marks = Marks()

        def read(vertices, whole=False, coarse=False):
            values = self.tape.five(vertices)
            if extras:
                tilt = None if whole else marks.tilt
                found, where = self.extra_tape.read(vertices, extras, tilt, None if whole else marks, coarse)
                marks.neck, marks.calf, marks.tilt = where.neck, where.calf, where.tilt
                values.update(found)
            return {key: values[key] for key in keys}

        start = read(rest, whole=True, coarse=True)
        crotch = start.get("crotch_height")
        deformation = Deformation(rest, joints, self.weights, self.bodies.fractions, crotch and crotch / 100.0)
        found = correct(deformation, read, asked, start=start)
        for last in range(FINAL_PASSES - 1, -1, -1) if extras and found.converged else ():
            corrected, _ = deformation.apply(found.theta)
            final = read(corrected, whole=True)
            offset = {key: final[key] - found.measured[key] for key in keys}
            found.measured = final
            if not last or all(abs(final[key] - asked[key]) <= AIM_CM for key in keys):
                break
            aimed = {key: asked[key] - offset[key] for key in keys}  # the loop's reading lacks the offset
            again = correct(deformation, read, aimed, theta=found.theta)
            found.theta, found.rounds, found.measured = again.theta, found.rounds + again.rounds, again.measured
        found.converged = all(abs(found.measured[key] - asked[key]) <= PROMISE_CM for key in keys)
        return found, deformation

    def refusal(self, asked, attempt, informed=None, tolerances=None):
        """The refusal's line: the blamed measurement, how far the body skin reaches, and why not further."""
        key = attempt.blamed
        start = attempt.correction.start[key]
        reach = bisect_reach(
            lambda trial: self.attempt(trial, True, informed, tolerances).problem is None, key, asked, start
        )
        return (
            f"body skin: {describe_reach(key, asked[key], start, reach)}: {attempt.problem}; "
            "ask nearer the set's bodies or use the pieces' skin"
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
