"""The extra measurements' smooth band search (core.measure.band_search.extremes_over_bands) against known extremes,
and the mannequin's measurements against main's (devkit.extra_before: golden section per band) on the shipped
sets and synthesized mannequins: the same values (1e-6 cm), the same local extremes."""

import itertools

import numpy as np
import pytest

from devkit.extra_before import MannequinLandmarksBefore, _farthest_distance, mannequin_extra_measurements_before
from devkit.toy import make_toy_mannequin
from ellimann_addon.core.constants import quartile_points
from ellimann_addon.core.mannequin.skeleton import JOINT_NAMES
from ellimann_addon.core.measure.band_search import BAND_SAMPLES, extreme_over_band, extremes_over_bands
from ellimann_addon.core.measure.extra import (
    SIDES,
    MannequinLandmarks,
    _farthest_points,
    mannequin_extra_measurements,
    split_measurements,
)
from ellimann_addon.core.measure.neck import HEAD_JOINT, NECK_JOINT, joint_tilt, neck_frame
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ellimann_addon.core.synthesis import synthesize as synthesis
from ellimann_addon.core.synthesis.shipped import FEMALE_SET, MALE_SET, named_reference_set

SAME_CM = 1e-6


def search(functions, bands, points=(), samples=BAND_SAMPLES):
    """extremes_over_bands with one plain function of the height per family."""

    def evaluate(family, heights):
        out = np.empty(len(heights))
        for index, function in enumerate(functions):
            rows = family == index
            out[rows] = function(heights[rows])
        return out

    return extremes_over_bands(evaluate, bands, points, samples)


def test_smooth_extremes_kinks_jumps_and_square_roots():
    functions = [
        lambda z: np.cos(3.0 * (z - 0.3137)),  # smooth: largest 1 at 0.3137
        lambda z: np.abs(z - 0.4711) + 0.2,  # a kink inside a piece: smallest 0.2
        lambda z: np.where(z > 0.6, 1.0 + np.sqrt(np.maximum(z - 0.6, 0.0)) - 2.0 * (z - 0.6), 1.0),  # sqrt at a break
        lambda z: np.where(z <= 0.5, 2.0, 1.0 + (z - 0.5)),  # a jump at a break: the limit 1 beside it
    ]
    bands = [
        (0, 0.0, 1.0, True, ()),
        (1, 0.0, 1.0, False, ()),
        (2, 0.0, 1.0, True, (0.6,)),
        (3, 0.0, 1.0, False, (0.5,)),
    ]
    extremes, at_points = search(functions, bands, [(0, 0.3137), (1, 0.0)])
    assert extremes[0] == pytest.approx(1.0, abs=1e-12)
    assert extremes[1] == pytest.approx(0.2, abs=1e-9)
    assert extremes[2] == pytest.approx(1.125, abs=1e-9)  # 1 + s - 2 s^2 at s = 1/4
    assert extremes[3] == pytest.approx(1.0, abs=1e-9)
    assert at_points == pytest.approx([1.0, 0.6711], abs=1e-12)


def test_every_local_dip_is_refined():
    """Two dips of near-equal depth, the grid's best sample beside the shallower one: both searches refine beside
    every local minimum of the grid and find the deeper one (refining only the best cell found the shallower)."""
    dips = lambda t: np.minimum((t - 0.2) ** 2, (t - 0.75) ** 2 - 0.001)  # noqa: E731
    value, where = extreme_over_band(dips, 0.0, 1.0, False, samples=7, where=True)
    assert value == pytest.approx(-0.001, abs=1e-9) and where == pytest.approx(0.75, abs=1e-4)
    assert search([dips], [(0, 0.0, 1.0, False, ())], samples=7)[0] == pytest.approx([-0.001], abs=1e-9)


def test_a_break_is_never_sampled_on():
    """A function that jumps at a break is sampled only beside it (END_PROBE inside each piece): which side of
    the break a sample falls on is never left to its last bits, and the limit either side counts."""
    heights = []

    def jump(z):
        heights.extend(np.ravel(z))
        return np.where(z < 0.5, 1.0, 2.0) + np.abs(z - 0.5)

    extremes, _ = search([jump], [(0, 0.0, 1.0, False, (0.5,))])
    assert extremes == pytest.approx([1.0], abs=1e-9)  # the limit below the break
    assert not np.any(np.asarray(heights) == 0.5)
    assert extreme_over_band(jump, 0.0, 1.0, False, breaks=(0.5,)) == pytest.approx(1.0, abs=1e-9)


def test_the_neck_joints_are_smpls():
    """core.measure (a floor below the skeleton) names the Neck and Head joints by their index."""
    assert (JOINT_NAMES[NECK_JOINT], JOINT_NAMES[HEAD_JOINT]) == ("Neck", "Head")
    frame = neck_frame(np.radians(20.0))
    assert np.allclose(frame @ frame.T, np.eye(3), atol=1e-15) and np.linalg.det(frame) == pytest.approx(1.0)
    assert frame[2] == pytest.approx([0.0, -np.sin(np.radians(20.0)), np.cos(np.radians(20.0))])  # leaning to -Y
    assert joint_tilt(None) is None


def test_an_empty_band_and_no_bands():
    extremes, at_points = search([lambda z: np.full(len(z), np.inf)], [(0, 0.0, 1.0, False, ())])
    assert extremes == [np.inf] and len(at_points) == 0


def synthesized(set_name, step):
    """Mannequins synthesized on every ``step``-th request of the set's inner-quartile grid (243 requests)."""
    reference = named_reference_set(set_name)
    requests = np.array(list(itertools.product(*[quartile_points(k, reference.ranges) for k in MEASUREMENTS])))
    batch = synthesis.synthesize_batch(reference, requests[::step])
    return [batch.mannequin(i, f"{set_name} {i}") for i in range(len(batch.measured))]


def assert_the_same_as_golden_section(mannequins):
    for mannequin in mannequins:
        now, before = mannequin_extra_measurements(mannequin), mannequin_extra_measurements_before(mannequin)
        for key in EXTRA_MEASUREMENTS:
            assert now[key] == pytest.approx(before[key], abs=SAME_CM), (mannequin.name, key)


@pytest.mark.parametrize("set_name", [FEMALE_SET, MALE_SET])
def test_the_same_as_golden_section_on_the_shipped_and_synthesized_mannequins(set_name):
    assert_the_same_as_golden_section(named_reference_set(set_name).mannequins + synthesized(set_name, 120))


@pytest.mark.slow
@pytest.mark.parametrize("set_name", [FEMALE_SET, MALE_SET])
def test_the_same_as_golden_section_on_a_ninth_of_the_grid(set_name):
    """27 synthesized mannequins per set (all 243 of each gave at most 2.7e-7 cm, the neck); the shipped ones are
    the test above's (which runs on numpy 1 and 2)."""
    assert_the_same_as_golden_section(synthesized(set_name, 9))


def test_the_toy_neck_tends_to_nothing():
    """The toy's neck band holds the tip of a piece (the section shrinks to a point): the smallest girth is the
    limit 0 there, which both searches approach only as far as their last probe; every other key agrees."""
    toy = make_toy_mannequin()
    now, before = mannequin_extra_measurements(toy), mannequin_extra_measurements_before(toy)
    assert 0.0 < now["neck"] < 0.01 and 0.0 < before["neck"] < 0.01
    for key in EXTRA_MEASUREMENTS[1:]:
        assert now[key] == pytest.approx(before[key], abs=SAME_CM, nan_ok=True), key


def test_the_farthest_points_stop_with_the_bits_of_a_hundred_steps():
    """The bisection stops when its bracket stops shrinking: the distances of main's 100 steps, bit for bit;
    the arm axes agree with main's (its tip from a second bisection) to rounding."""
    for mannequin in named_reference_set(FEMALE_SET).mannequins:
        marks, before = MannequinLandmarks(mannequin), MannequinLandmarksBefore(mannequin)
        for side, (start, axis, length) in zip(SIDES, marks.arm_axes()):
            arm = marks.arm_mask(side)
            rotation, center, semi = mannequin.rotation[arm], mannequin.center[arm], mannequin.semi_axes[arm]
            assert np.array_equal(
                _farthest_points(rotation, center, semi, start)[0], _farthest_distance(rotation, center, semi, start)
            )
            old_start, old_axis, old_length = before.arm_axis(side)
            assert np.array_equal(start, old_start) and length == old_length
            assert axis == pytest.approx(old_axis, abs=1e-12)


def test_split_measurements_parts_the_five_from_the_extra_ones():
    values = {"neck": 33.0, "He": 160.0, "Sh": 40.0, "Br": 95.0, "Wa": 80.0, "Hi": 105.0, "thigh": 55.0}
    five, extra = split_measurements(values)
    assert list(five) == ["He", "Sh", "Br", "Wa", "Hi"] and five["Br"] == 95.0
    assert extra == {"neck": 33.0, "thigh": 55.0}
