import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from devkit.toy import rotation_from_vector
from ellimann_addon.core import adjust, clean
from ellimann_addon.core.constants import MEASUREMENTS
from ellimann_addon.core.ellipsoid import shape_matrix
from ellimann_addon.core.errors import MeasurementError


def test_stretch_is_the_exact_affine_image_for_axis_aligned_ellipsoids():
    rotation = np.eye(3)[[2, 0, 1]].T  # a proper permutation: local axes along world axes
    center, semi = np.array([0.1, -0.2, 0.9]), np.array([0.05, 0.08, 0.12])
    scale, origin = np.array([1.3, 0.8, 1.1]), np.array([0.0, 0.05, 0.2])
    r, c, d = adjust.stretch(rotation, center, semi, scale, origin)
    a = np.diag(scale)
    assert np.array_equal(r, rotation)
    assert np.allclose(shape_matrix(r, d), a @ shape_matrix(rotation, semi) @ a.T)
    assert np.allclose(c, origin + a @ (center - origin))


@settings(max_examples=30, deadline=None)
@given(st.lists(st.floats(-3, 3), min_size=3, max_size=3), st.floats(0.5, 2.0))
def test_uniform_stretch_scales_any_ellipsoid_exactly(rotvec, factor):
    rotation = rotation_from_vector(rotvec)
    semi = np.array([0.05, 0.08, 0.12])
    r, c, d = adjust.stretch(rotation, np.zeros(3), semi, np.full(3, factor), np.zeros(3))
    assert np.allclose(shape_matrix(r, d), factor ** 2 * shape_matrix(rotation, semi))


def test_targets_equal_to_the_measurements_change_nothing(toy):
    result = adjust.adjust_to_measurements(toy, toy.measure())
    assert result.converged and result.iterations == 0
    assert all(f == 1.0 for f in result.factors.values())
    assert np.allclose(result.mannequin.center, toy.center, rtol=0.0, atol=1e-15)


@pytest.mark.parametrize("factors", [(1.05, 0.95, 1.06, 0.94, 1.04), (0.97, 1.08, 0.95, 1.05, 0.96)])
def test_adjustment_meets_every_target(toy, factors):
    before = toy.copy()
    targets = {key: value * f for (key, value), f in zip(toy.measure().items(), factors)}
    result = adjust.adjust_to_measurements(toy, targets, tolerance=1e-6)
    assert result.converged
    measured = result.mannequin.measure()
    for key in MEASUREMENTS:
        assert measured[key] == pytest.approx(targets[key], rel=1e-6)
        assert result.measured[key] == pytest.approx(measured[key], rel=1e-12)
    assert np.array_equal(toy.center, before.center) and np.array_equal(toy.semi_axes, before.semi_axes)
    assert np.array_equal(result.mannequin.rotation, toy.rotation)  # frames are kept
    assert np.all(result.mannequin.semi_axes > 0)


def test_a_subset_of_targets_moves_only_its_controls(toy):
    measured = toy.measure()
    result = adjust.adjust_to_measurements(toy, {"He": measured["He"] * 1.1}, tolerance=1e-8)
    assert result.mannequin.measure()["He"] == pytest.approx(measured["He"] * 1.1, rel=1e-8)
    assert [result.factors[k] for k in ("Sh", "Br", "Wa", "Hi")] == [1.0] * 4


def test_symmetric_mannequins_stay_symmetric(toy):
    symmetric = clean.symmetrize(toy)
    targets = {key: value * 1.04 for key, value in symmetric.measure().items()}
    result = adjust.adjust_to_measurements(symmetric, targets)
    assert result.converged
    assert clean.asymmetry(result.mannequin) < 1e-12


def test_the_shoulder_control_moves_the_arms_without_reshaping_them(toy):
    targets = dict(toy.measure())
    targets["Sh"] *= 1.1
    result = adjust.adjust_to_measurements(toy, targets, tolerance=1e-8)
    arm = toy.topology.index["5.a Arm.L"]
    assert np.allclose(result.mannequin.semi_axes[arm], toy.semi_axes[arm], rtol=1e-6)
    assert result.mannequin.center[arm, 0] > toy.center[arm, 0]


@pytest.mark.parametrize("targets, field", [
    ({"He": -1.0}, "He"), ({"Br": float("nan")}, "Br"), ({"Wa": True}, "Wa"), ({"Knee": 40.0}, "Knee"),
    ({"Hi": "90"}, "Hi"), ({}, "targets"),
])
def test_bad_targets_are_refused_by_name(toy, targets, field):
    before = toy.copy()
    with pytest.raises(MeasurementError) as info:
        adjust.adjust_to_measurements(toy, targets)
    assert info.value.field == field
    assert np.array_equal(toy.center, before.center)


def test_a_section_that_cuts_no_part_cannot_be_adjusted(toy):
    lifted = toy.copy()
    belly = [toy.topology.index[n] for n in ("2.b Belly", "2.a Chest", "3.a Pelvis", "4.a Trapezius.L",
                                             "4.a Trapezius.R", "6.a Thigh.L", "6.a Thigh.R")]
    lifted.semi_axes[belly] *= 0.2  # no girth part reaches the sections any more
    with pytest.raises(MeasurementError, match="no part crosses its section") as info:
        adjust.adjust_to_measurements(lifted, {"Wa": 70.0})
    assert info.value.field == "Wa"
