"""The body skin (core.body): a request at a body's own measurements gives that body back, the skin measures the
request within 1 mm by the body-mesh measurer (the five, and any of the six extras) on female and male, the mesh
stays closed, 2-manifold, of Euler characteristic 2 and free of self-intersections, and a request beyond the
bodies is refused in one line."""

import numpy as np
import pytest

from devkit.mesh_checks import self_intersections
from ellimann_addon.core.body.correct import PROMISE_CM, BodySkinError
from ellimann_addon.core.body.deform import PARAMETERS, Deformation, hat
from ellimann_addon.core.body.mesh_checks import arm_clearance, fold_problems, surface_problems
from ellimann_addon.core.body.skin import BodySkinMaker
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ellimann_addon.core.synthesis.bodies import load_set_bodies
from ellimann_addon.core.synthesis.shipped import named_reference_set, reference_folder
from tools.shipped.reference_sets import SHARED

SETS = ("female", "male")
BANK = SHARED / "bodies"
VOLUME_TOLERANCE = 0.03  # every standard pose and walk frame (issue 42)


@pytest.fixture(scope="module", params=SETS)
def maker(request):
    reference = named_reference_set(request.param)
    made = BodySkinMaker(load_set_bodies(reference_folder(request.param)), ranges=reference.ranges)
    made.reference = reference
    return made


def five(values):
    return {key: values[key] for key in MEASUREMENTS}


def grid_requests(ranges, count, seed):
    """``count`` points of the 3^5 grid over ``ranges`` (the 243 grid), drawn at random."""
    rng = np.random.default_rng(seed)
    levels = {key: (lo, 0.5 * (lo + hi), hi) for key, (lo, hi) in ranges.items()}
    picks = rng.integers(0, 3, size=(count, len(MEASUREMENTS)))
    return [{key: levels[key][i] for key, i in zip(MEASUREMENTS, row)} for row in picks]


def test_a_request_at_a_body_s_own_measurements_gives_that_body_back(maker):
    bodies = maker.bodies
    for i in range(len(bodies)):
        skin = maker.make(five(bodies.measurements(i)))
        own = bodies.vertices(i) - [0.0, 0.0, bodies.vertices(i)[:, 2].min()]
        assert np.abs(skin.vertices - own).max() < 5e-4  # the correction moves it by the tape's tolerance only
        assert np.abs(skin.joints - (bodies.joints[i] - [0.0, 0.0, bodies.vertices(i)[:, 2].min()])).max() < 1e-3
        assert skin.rounds <= 1


def test_on_the_243_grid_each_request_is_met_within_a_millimetre_or_refused_in_one_line(maker):
    """The grid's corners combine measurements no body of the set has (narrow shoulders over a 153 cm bust):
    the correction refuses those (docs/body_skin.md counts them over the whole grid), naming the measurement."""
    met = 0
    for request in grid_requests(maker.reference.ranges, 10, 42):
        try:
            skin = maker.make(request)
        except BodySkinError as error:
            message = str(error)
            assert "\n" not in message and message.startswith("body skin: ") and " cm " in message
            assert any(f" {key} " in f" {message}" for key in MEASUREMENTS)
            continue
        found = skin.measure().values  # the whole measurer, not the loop's tape
        assert max(abs(found[key] - request[key]) for key in MEASUREMENTS) <= PROMISE_CM
        met += 1
    assert met >= 3


def test_the_five_are_met_within_a_millimetre_on_bodies_of_the_bank(maker):
    """Requests that are bodies (../shared/bodies: 80 bodies the shipped sets have not seen)."""
    bank = np.load(BANK / f"{maker.reference.name}.npz")
    met = 0
    for row in bank["measurements_cm"][::8]:
        request = dict(zip(MEASUREMENTS, row.tolist()))
        try:
            found = maker.make(request).measure().values
        except BodySkinError as error:  # shoulders far narrower than the bodies' blend fold (docs/body_skin.md)
            assert "\n" not in str(error) and str(error).startswith("body skin: ")
            continue
        assert max(abs(found[key] - request[key]) for key in MEASUREMENTS) <= PROMISE_CM
        met += 1
    assert met >= 8


def test_the_eleven_are_met_on_bodies_the_set_has_not_seen(maker):
    """Requests with the six extras: the measurements of the set's own bodies moved by a few centimetres (each
    a plausible body's eleven)."""
    rng = np.random.default_rng(7)
    bodies = maker.bodies
    for i in (0, 3):
        own = bodies.measurements(i)
        request = {key: value * (1.0 + rng.uniform(-0.03, 0.03)) for key, value in own.items()}
        extra = {key: request[key] for key in EXTRA_MEASUREMENTS}
        skin = maker.make(five(request), extra)
        found = skin.measure().values
        assert max(abs(found[key] - request[key]) for key in request) <= PROMISE_CM, skin.misses()


def test_the_skin_stays_a_closed_unfolded_sphere_without_self_intersections(maker):
    bodies = maker.bodies
    own = self_intersections(bodies.vertices(4), bodies.faces)  # the body model's own mesh, as made
    request = {key: value * 1.06 for key, value in five(bodies.measurements(4)).items()}
    skin = maker.make(request)
    assert surface_problems(skin.vertices, skin.faces) == []
    assert fold_problems(maker.interpolated(request)[0], skin.vertices, skin.faces) == []
    assert len(self_intersections(skin.vertices, skin.faces)) <= len(own)
    assert all(arm_clearance(skin.vertices, bodies.arms, bodies.fractions).values())


def test_the_deformations_are_smooth_and_each_moves_its_own_measurement_most(maker):
    bodies = maker.bodies
    rest, joints = maker.interpolated(five(bodies.measurements(4)))
    deformation = Deformation(rest, joints, bodies.dense_weights, bodies.fractions)
    z = np.linspace(0.0, 1.0, 2001)
    profile = hat(z, 0.2, 0.5, 0.7)
    assert profile.max() == 1.0 and np.abs(np.diff(profile, 2)).max() < 1e-4  # no kink (C1)
    start = maker.tape.measure(rest, MEASUREMENTS)
    for key in MEASUREMENTS:
        theta = np.zeros(len(PARAMETERS))
        theta[PARAMETERS.index(key)] = 0.01 if key == "Sh" else 0.05
        moved = maker.tape.measure(deformation.apply(theta)[0], MEASUREMENTS)
        change = {k: abs(moved[k] - start[k]) / start[k] for k in MEASUREMENTS}
        assert max(change, key=change.get) == key


def test_a_request_beyond_the_bodies_is_refused_in_one_line_naming_the_measurement(maker):
    request = five(maker.bodies.measurements(4))
    request["Wa"] *= 1.8
    with pytest.raises(BodySkinError) as caught:
        maker.make(request)
    message = str(caught.value)
    assert "\n" not in message and message.startswith("body skin: ") and " Wa " in message and "cm" in message


def test_posed_in_every_standard_pose_and_walk_frame_the_volume_is_kept(maker):
    from ellimann_addon.core.geometry.mesh import volume
    from ellimann_addon.core.mannequin.skeleton import JOINT_INDEX
    from ellimann_addon.core.pose.kinematics import forward_kinematics
    from ellimann_addon.core.pose.motion import clamped_motion
    from ellimann_addon.core.pose.standard import POSE_NAMES

    skin = maker.make(five(maker.bodies.measurements(4)))
    rest = skin.volume
    index, weight = skin.bones()
    elbow = JOINT_INDEX["L_Elbow"]
    arm = np.isin(index, [elbow, JOINT_INDEX["L_Shoulder"]]).any(axis=1)
    depth = np.linalg.norm(skin.vertices[arm] - skin.joints[elbow], axis=1).min()
    for name in POSE_NAMES:
        frames = clamped_motion(name, skin.joints)[0]
        for pose in frames[:: max(1, len(frames) // 3)]:
            moved = skin.posed(pose)
            assert abs(volume(moved, skin.faces) / rest - 1.0) <= VOLUME_TOLERANCE, name
            points = forward_kinematics(skin.joints, pose.rotations, pose.translation)[2]
            assert np.linalg.norm(moved[arm] - points[elbow], axis=1).min() >= 0.8 * depth, name
