"""How far the body skin reaches (core.body.plausible, core.body.deform): the deformations' profiles and smoothing
against their closed forms, the stretch of a triangle, a request's trunk taper, a refusal that says how far the
body skin goes (and it does go that far), the arms raised to clear a wide trunk, and every made skin unfolded,
within the stretch allowed and with its arms clear of its trunk."""

import numpy as np
import pytest

from ellimann_addon.core.body.correct import PROMISE_CM, BodySkinError
from ellimann_addon.core.body.deform import abducted, cardinal, smoothed
from ellimann_addon.core.body.mesh_checks import arm_intrusion, fold_problems, principal_stretches
from ellimann_addon.core.body.plausible import (
    INTRUSION_TOLERANCE,
    STRETCH_ALLOWANCE,
    STRETCH_RANGE,
    TAPER_MARGIN,
    TAPERS,
    proportion_problem,
)
from ellimann_addon.core.body.skin import BodySkinMaker
from ellimann_addon.core.mannequin.skeleton import JOINT_INDEX
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.bodies import load_set_bodies
from ellimann_addon.core.synthesis.shipped import named_reference_set, reference_folder


@pytest.fixture(scope="module")
def female():
    reference = named_reference_set("female")
    made = BodySkinMaker(load_set_bodies(reference_folder("female")), ranges=reference.ranges)
    made.reference = reference
    return made


def corner(maker, levels):
    """The grid request at ``levels`` (0 low, 1 middle, 2 high of each of the five in the set's ranges)."""
    ranges = maker.reference.ranges
    return {
        key: ranges[key][0] + 0.5 * level * (ranges[key][1] - ranges[key][0])
        for key, level in zip(MEASUREMENTS, levels)
    }


def test_a_profile_is_1_at_its_section_0_at_the_others_and_smooth_between():
    knots = [0.38, 0.5, 0.645, 0.72, 0.845]
    for k in (1, 2, 3):
        assert np.allclose(cardinal(np.array(knots), knots, k), np.eye(5)[k], atol=1e-12)
        z = np.linspace(0.3, 0.9, 60001)
        profile = cardinal(z, knots, k)
        slope = np.gradient(profile, z)
        assert np.abs(np.diff(slope)).max() < 1e-2  # C1 everywhere (the ends included)
        inner = (z > knots[0] + 1e-3) & (z < knots[-1] - 1e-3)
        assert np.abs(np.diff(np.gradient(slope, z)[inner])).max() < 0.5  # C2 between the ends
        assert profile[(z < knots[0]) | (z > knots[-1])].max() == 0.0
    total = sum(cardinal(z, knots, k) for k in (1, 2, 3))
    between = total[(z >= knots[1]) & (z <= knots[3])]
    assert between.min() > 0.99 and between.max() < 1.15  # all three scaled alike: the trunk nearly uniformly


def test_smoothing_keeps_constants_and_the_weights_sum(female):
    bodies = female.bodies
    constant = np.full((len(bodies.mean), 2), 0.25)
    assert np.allclose(smoothed(constant, bodies.faces, 10), 0.25)
    weights = smoothed(bodies.dense_weights, bodies.faces, 5)
    assert np.allclose(weights.sum(axis=1), 1.0) and weights.min() >= 0.0
    assert np.abs(weights - bodies.dense_weights).max() > 0.1  # seams spread


def test_principal_stretches_of_scales_rotations_and_a_shear():
    faces = np.array([[0, 1, 2]])
    triangle = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    small, large = principal_stretches(triangle, 2.5 * triangle, faces)
    assert np.allclose([small[0], large[0]], [2.5, 2.5])
    angle = 0.7
    turn = np.array([[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    assert np.allclose(np.concatenate(principal_stretches(triangle, triangle @ turn.T, faces)), 1.0)
    small, large = principal_stretches(triangle, triangle * [3.0, 0.5, 1.0], faces)
    assert np.allclose([small[0], large[0]], [0.5, 3.0])


def test_a_request_s_trunk_taper_is_refused_beyond_the_bodies_naming_how_far_it_may_go(female):
    fractions = female.bodies.fractions
    request = {"He": 160.0, "Sh": 42.0, "Br": 150.0, "Wa": 63.0, "Hi": 100.0}
    line, key = proportion_problem(request, fractions)
    distance = (fractions["Br"] - fractions["Wa"]) * request["He"]
    taper = (request["Br"] - request["Wa"]) / (2.0 * np.pi * distance)
    assert key == "Br" and f"{taper:+.2f}" in line and "\n" not in line
    allowed = TAPERS[("Br", "Wa")][1] + TAPER_MARGIN
    most = request["Wa"] + allowed * 2.0 * np.pi * distance  # the largest bust over this waist
    assert f"Br at most {most:.1f} cm" in line
    assert proportion_problem({**request, "Br": most - 0.05}, fractions) == (None, None)
    assert proportion_problem({**request, "Br": 100.0}, fractions) == (None, None)
    with pytest.raises(BodySkinError) as caught:
        female.make(request)
    assert str(caught.value).startswith("body skin: Br 150.0 cm over Wa 63.0 cm")


def test_a_refused_shoulder_width_names_its_reach_and_the_body_skin_goes_that_far(female):
    """Narrow shoulders over a wide chest: the arms would cut into it even raised; the refusal says how far the
    shoulders can narrow, and a request at that width is made and measures it."""
    request = corner(female, (1, 0, 2, 1, 1))  # Sh 30 cm over a 153 cm bust
    with pytest.raises(BodySkinError) as caught:
        female.make(request)
    message = str(caught.value)
    assert message.startswith("body skin: Sh 30.0 cm") and "the body skin reaches" in message and "\n" not in message
    reach = float(message.split("reaches ")[1].split(" cm")[0])
    assert 30.0 < reach < 53.0
    skin = female.make({**request, "Sh": reach + 0.1})  # the reach is rounded to a millimetre
    found = skin.measure().values
    assert max(abs(found[key] - skin.request[key]) for key in MEASUREMENTS) <= PROMISE_CM


def test_arms_raised_to_clear_a_wide_trunk_and_the_shoulders_still_met(female):
    request = corner(female, (1, 0, 1, 1, 1))  # Sh 30 cm over the middle of every girth
    skin = female.make(request)
    assert 0.0 < skin.abduction <= np.radians(20.0)
    assert arm_intrusion(skin.vertices, skin.faces, female.bodies.arms)[0] <= INTRUSION_TOLERANCE
    found = skin.measure().values
    assert max(abs(found[key] - request[key]) for key in MEASUREMENTS) <= PROMISE_CM
    rest, joints = female.interpolated(request)
    again, moved = abducted(rest, joints, female.weights, skin.abduction)
    elbow = JOINT_INDEX["L_Elbow"]
    assert moved[elbow, 0] > joints[elbow, 0]  # the left elbow raised outwards, about its shoulder
    shoulder = JOINT_INDEX["L_Shoulder"]
    assert np.isclose(np.linalg.norm(moved[elbow] - moved[shoulder]), np.linalg.norm(joints[elbow] - joints[shoulder]))


@pytest.mark.slow
def test_every_made_skin_of_the_grid_s_middle_layer_is_unfolded_within_the_stretch_and_clear(female):
    """The 81 requests of the 243 grid at the middle height: each made or refused in one line; every one made
    unfolded, no more triangles stretched beyond STRETCH_RANGE than allowed, its arms clear of its trunk and
    measuring the request within a millimetre."""
    import itertools

    made = 0
    for levels in itertools.product(range(3), repeat=4):
        request = corner(female, (1, *levels))
        try:
            skin = female.make(request)
        except BodySkinError as error:
            assert "\n" not in str(error) and str(error).startswith("body skin: ")
            continue
        rest = female.attempt(request, check=False).deformation.rest
        assert fold_problems(rest, skin.vertices, skin.faces, STRETCH_ALLOWANCE) == []
        small, large = principal_stretches(rest, skin.vertices, skin.faces)
        beyond = (small < STRETCH_RANGE[0]) | (large > STRETCH_RANGE[1])
        assert beyond.sum() <= STRETCH_ALLOWANCE * len(skin.faces)
        assert arm_intrusion(skin.vertices, skin.faces, female.bodies.arms)[0] <= INTRUSION_TOLERANCE
        found = skin.measure().values
        assert max(abs(found[key] - request[key]) for key in MEASUREMENTS) <= PROMISE_CM
        made += 1
    assert made >= 20  # a quarter at least: the grid's corners hold combinations no body has (docs/body_skin.md)
