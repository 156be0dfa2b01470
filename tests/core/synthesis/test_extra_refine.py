"""Exact mode with the extra measurements (core.synthesis.extra_refine): each degree of freedom meets its measurement
within 1 mm with the five kept exact, on slim and heavy requests (the heavy bodies' neck and thigh were missed
before); the girth deformations widen a section without moving what they must keep; contradictions are refused
with the amount."""

import numpy as np
import pytest

from ellimann_addon.core.geometry.ellipsoid import axis_extent
from ellimann_addon.core.measure.extra import (
    THIGH_DROP,
    MannequinLandmarks,
    mannequin_extra_measurements,
    mannequin_neck,
    neck_plane,
)
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ellimann_addon.core.synthesis.extra_refine import (
    EXTRA_FACTOR_LIMIT,
    MISS_CM,
    NECK_TIP,
    ExtraRequestError,
    _apply,
    _section_rows,
    _widen_at,
    extra_request_problems,
)
from ellimann_addon.core.synthesis.reference_set import ReferenceSet
from ellimann_addon.core.synthesis.shipped import named_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize_extra

FIVE_RELATIVE = 1e-5  # the five's exact-mode tolerance (0.001 %)
# The five and the six of two of ../shared/refmodels' bodies as measured as meshes (docs/measurements.md).
SLIM = dict(zip(MEASUREMENTS, (148.0, 31.11, 84.97, 63.0, 83.0)))
SLIM_EXTRA = {
    "neck": 27.59,
    "upper_arm": 19.95,
    "thigh": 43.85,
    "calf": 32.30,
    "crotch_height": 67.17,
    "arm_length": 57.02,
}
TALL = dict(zip(MEASUREMENTS, (170.99, 30.22, 83.98, 62.99, 84.01)))
TALL_EXTRA = {
    "neck": 29.03,
    "upper_arm": 19.50,
    "thigh": 43.55,
    "calf": 35.17,
    "crotch_height": 80.07,
    "arm_length": 64.09,
}
HEAVY = dict(zip(MEASUREMENTS, (148.64, 47.69, 144.41, 138.79, 152.08)))
HEAVY_EXTRA = {
    "neck": 36.95,
    "upper_arm": 26.12,
    "thigh": 86.13,
    "calf": 47.40,
    "crotch_height": 65.38,
    "arm_length": 55.83,
}


@pytest.fixture(scope="module")
def reference():
    return named_reference_set("female")


def assert_met(reference, five, extra):
    start = synthesize_extra(reference, five, {})[0]
    mannequin, measured, _, missed = synthesize_extra(reference, five, extra)
    # no piece deformed past recognition (the thigh's and calf's steps once ratcheted a calf to half its depth;
    # a slim thigh asked 10% under the set's is 26% shallower front to back: the legs narrow only so)
    ratio = mannequin.semi_axes / start.semi_axes
    assert ratio.min() > 0.7 and ratio.max() < 1.6, (ratio.min(), ratio.max())
    assert not missed, missed
    for key, value in extra.items():
        assert abs(measured[key] - value) <= MISS_CM, (key, measured[key], value)
    for key, value in five.items():
        assert abs(measured[key] / value - 1.0) <= FIVE_RELATIVE, (key, measured[key], value)
    # what is reported is what the mannequin measures
    again = mannequin_extra_measurements(mannequin)
    assert all(again[key] == pytest.approx(measured[key], abs=1e-9) for key in EXTRA_MEASUREMENTS)
    return mannequin


@pytest.mark.parametrize("key", EXTRA_MEASUREMENTS)
@pytest.mark.parametrize("body", ["slim", "heavy"])
def test_each_extra_measurement_of_a_body_is_met_alone(reference, key, body):
    five, extra = (SLIM, SLIM_EXTRA) if body == "slim" else (HEAVY, HEAVY_EXTRA)
    assert_met(reference, five, {key: extra[key]})


@pytest.mark.parametrize(
    "five, extra", [(SLIM, SLIM_EXTRA), (TALL, TALL_EXTRA), (HEAVY, HEAVY_EXTRA)], ids=["slim", "tall", "heavy"]
)
def test_all_six_of_a_body_are_met_at_once(reference, five, extra):
    assert_met(reference, five, extra)


@pytest.mark.slow
@pytest.mark.parametrize("key", EXTRA_MEASUREMENTS)
@pytest.mark.parametrize("ratio", [0.9, 1.12])
@pytest.mark.parametrize("body", ["slim", "heavy"])
def test_a_grid_of_requests_around_what_the_reference_set_gives_is_met(reference, key, ratio, body):
    five = SLIM if body == "slim" else HEAVY
    start = synthesize_extra(reference, five, {})[1][key]
    assert_met(reference, five, {key: ratio * start})


def test_a_thigh_widened_keeps_its_mid_plane_edge_and_far_ends(reference):
    """A leg piece crossing the mid-plane would lower the crotch, and with it the thigh's own section (the
    heavy thigh was missed so): the pieces the section cuts grow away from the mid-plane, and a piece lengthened
    keeps the end away from the section."""
    mannequin = synthesize_extra(reference, HEAVY, {})[0]
    marks = MannequinLandmarks(mannequin)
    z = marks.bottom + marks.crotch() - THIGH_DROP * marks.height
    legs = marks.leg_mask("L") | marks.leg_mask("R")
    rotation, center, semi = mannequin.rotation, mannequin.center.copy(), mannequin.semi_axes.copy()
    rows, cut, half = _section_rows(rotation, center, semi, z, legs)
    assert len(rows) >= 2  # the thigh and the hip of each side
    inner = np.abs(center[rows, 0] - marks.mid_x) - axis_extent(rotation[rows], semi[rows], 0)
    far = center[rows, 2] - np.sign(cut) * half
    before = marks.girths_at([z], marks.leg_mask("L"))[0]
    _widen_at(
        rotation, center, semi, z, legs, 1.2, 2.0, np.zeros(len(center)), np.zeros(len(center)), mid_x=marks.mid_x
    )
    widened = mannequin.copy(center=center, semi_axes=semi)
    after = MannequinLandmarks(widened)
    assert after.crotch() == pytest.approx(marks.crotch(), abs=1e-9)
    new_inner = np.abs(center[rows, 0] - marks.mid_x) - axis_extent(rotation[rows], semi[rows], 0)
    assert np.allclose(new_inner, inner, atol=1e-12)
    # the far end stays (within 0.5 mm: a tilted piece's semi-axes are stretched by their share along z)
    assert np.allclose(center[rows, 2] - np.sign(cut) * axis_extent(rotation[rows], semi[rows], 2), far, atol=5e-4)
    assert after.girths_at([z], after.leg_mask("L"))[0] > 1.1 * before
    untouched = np.setdiff1d(np.arange(len(center)), rows)
    assert np.array_equal(center[untouched], mannequin.center[untouched])


def test_narrowing_shortens_a_piece_only_back_to_its_own_length(reference):
    mannequin = synthesize_extra(reference, HEAVY, {})[0]
    marks = MannequinLandmarks(mannequin)
    z = marks.bottom + 0.4 * marks.crotch()  # the calves
    legs = marks.leg_mask("L") | marks.leg_mask("R")
    rotation, center, semi = mannequin.rotation, mannequin.center.copy(), mannequin.semi_axes.copy()
    height = axis_extent(rotation, semi, 2)
    rows = _section_rows(rotation, center, semi, z, legs)[0]
    stretch, spread = np.zeros(len(center)), np.zeros(len(center))
    _widen_at(rotation, center, semi, z, legs, 0.9, 2.0, stretch, spread)  # from the start: across only
    # (a tilted piece's height changes a little with its across axes: they lean)
    assert np.allclose(axis_extent(rotation, semi, 2)[rows], height[rows], rtol=5e-3) and not stretch.any()
    _widen_at(rotation, center, semi, z, legs, 1.2, 2.0, stretch, spread)
    assert (axis_extent(rotation, semi, 2)[rows] > height[rows]).all() and (stretch[rows] > 0.0).all()
    for _ in range(3):  # narrowing past the lengthening: back to its own length, never shorter
        _widen_at(rotation, center, semi, z, legs, 0.8, 2.0, stretch, spread)
        assert (stretch >= -1e-15).all()
    assert np.allclose(stretch, 0.0, atol=1e-12)
    # its own length but for the lean of its across axes, narrowed by 0.6 in all
    assert np.allclose(axis_extent(rotation, semi, 2)[rows], height[rows], rtol=2e-2)


def test_widening_lengthens_a_piece_at_most_by_the_factor_limit(reference):
    mannequin = synthesize_extra(reference, HEAVY, {})[0]
    marks = MannequinLandmarks(mannequin)
    z = marks.bottom + marks.crotch() - THIGH_DROP * marks.height
    legs = marks.leg_mask("L") | marks.leg_mask("R")
    rotation, center, semi = mannequin.rotation, mannequin.center.copy(), mannequin.semi_axes.copy()
    rows = _section_rows(rotation, center, semi, z, legs)[0]
    limit = np.log(EXTRA_FACTOR_LIMIT)
    free_center, free_semi = center.copy(), semi.copy()
    _widen_at(
        rotation,
        free_center,
        free_semi,
        z,
        legs,
        1.5,
        2.0,
        np.zeros(len(center)),
        np.zeros(len(center)),
        mid_x=marks.mid_x,
    )
    stretch = np.zeros(len(center))
    stretch[rows] = limit - 0.01  # lengthened nearly to the limit already
    _widen_at(rotation, center, semi, z, legs, 1.5, 2.0, stretch, np.zeros(len(center)), mid_x=marks.mid_x)
    assert np.allclose(stretch[rows], limit, atol=1e-12)
    # 0.01 of lengthening where it would be 2 |cut| log 1.5: shorter, and the rest went across (front to back)
    assert (axis_extent(rotation, semi, 2)[rows] < axis_extent(rotation, free_semi, 2)[rows]).all()
    assert (axis_extent(rotation, semi, 1)[rows] > axis_extent(rotation, free_semi, 1)[rows]).all()


def test_widening_scales_a_piece_across_at_most_by_the_factor_limit(reference):
    """The limit is each piece's: a piece scaled across nearly to it takes only what is left, one at it
    nothing more (and narrowing may still bring it back)."""
    mannequin = synthesize_extra(reference, HEAVY, {})[0]
    marks = MannequinLandmarks(mannequin)
    z = marks.bottom + 0.4 * marks.crotch()  # the calves: cut near their middle, mostly scaled across
    legs = marks.leg_mask("L") | marks.leg_mask("R")
    rotation, center, semi = mannequin.rotation, mannequin.center.copy(), mannequin.semi_axes.copy()
    rows = _section_rows(rotation, center, semi, z, legs)[0]
    limit = np.log(EXTRA_FACTOR_LIMIT)
    spread = np.zeros(len(center))
    spread[rows] = limit - 0.01
    _widen_at(rotation, center, semi, z, legs, 1.5, 2.0, np.zeros(len(center)), spread)
    assert np.allclose(spread[rows], limit, atol=1e-12)
    free_center, free_semi = center.copy(), semi.copy()  # the same pieces, not scaled across before
    free_before = semi.copy()
    _widen_at(rotation, free_center, free_semi, z, legs, 1.5, 2.0, np.zeros(len(center)), np.zeros(len(center)))
    _widen_at(rotation, center, semi, z, legs, 1.5, 2.0, np.zeros(len(center)), spread)
    assert np.allclose(spread[rows], limit, atol=1e-12)
    # only lengthened (reaching a little further sideways as they lean), not scaled across: much narrower
    before, grown, free = (axis_extent(rotation, s, 1)[rows] for s in (free_before, semi, free_semi))
    assert (grown - before < 0.5 * (free - before)).all()
    _widen_at(rotation, center, semi, z, legs, 0.9, 2.0, np.zeros(len(center)), spread)
    assert (spread[rows] < limit).all()


def test_the_neck_widens_square_to_the_neck_and_leaves_the_tips_it_cuts(reference):
    """The heavy body's neck section (square to the neck) cuts the face, the neck piece and the trapezius tips:
    widening it changes the face and the neck, not the trapezius (lengthened from a tip, a piece ran up the neck:
    held-out tall_slim's upper back did, its smallest section jumped to the head and the head was narrowed to
    0.72 to meet it)."""
    mannequin = synthesize_extra(reference, HEAVY, {})[0]
    names = [part.name for part in mannequin.topology]
    frame, origin, offset = neck_plane(mannequin)
    rows, cut, _ = _section_rows(
        frame @ mannequin.rotation,
        (mannequin.center - origin) @ frame.T,
        mannequin.semi_axes,
        offset,
        np.ones(len(names), bool),
    )
    tips = rows[np.abs(cut) >= NECK_TIP]
    assert {names[i] for i in tips} == {"10.a Trapezius.L", "10.a Trapezius.R"}
    rotation, center, semi = mannequin.rotation, mannequin.center.copy(), mannequin.semi_axes.copy()
    zeros = np.zeros(len(names))
    _apply("neck", 1.2, mannequin, rotation, center, semi, zeros.copy(), zeros.copy())
    changed = np.nonzero(np.any(semi != mannequin.semi_axes, axis=1) | np.any(center != mannequin.center, axis=1))[0]
    assert {names[i] for i in changed} == {"1.b Face", "2.a Neck"}
    before, after = mannequin_neck(mannequin)[0], mannequin_neck(mannequin.copy(center=center, semi_axes=semi))[0]
    assert after > 1.05 * before


def test_a_heavy_neck_is_met_by_a_set_that_has_not_seen_the_body(reference):
    """The shipped set without small_chubby's RM starts her neck at some 24 cm where 42.64 is asked (her level
    neck before issue 26; square to the neck she measures 36.95): a factor near 2 that the neck piece, cut off its
    middle, takes only partly each way. A limit on the measurement's factor stopped it at 39 cm and the start was
    returned, the neck missed; each piece's own limit lets it reach (bench_scan_held_out: small_chubby,
    tall_chubby and average missed their neck so)."""
    asked = 42.64
    keep = [i for i, name in enumerate(reference.names) if name != "small_chubby"]
    four = ReferenceSet([reference.mannequins[i] for i in keep], names=[reference.names[i] for i in keep])
    start, start_measured, _, _ = synthesize_extra(four, HEAVY, {})
    assert start_measured["neck"] < 0.6 * asked  # the case: far below what is asked
    mannequin, measured, _, missed = synthesize_extra(four, HEAVY, {"neck": asked})
    assert not missed, missed
    assert abs(measured["neck"] - asked) <= MISS_CM, measured["neck"]
    assert all(abs(measured[key] / value - 1.0) <= FIVE_RELATIVE for key, value in HEAVY.items())
    ratio = mannequin.semi_axes / start.semi_axes  # the neck nearly doubled, as asked, but no piece beyond the limit
    assert 1.0 / EXTRA_FACTOR_LIMIT <= ratio.min() and ratio.max() <= EXTRA_FACTOR_LIMIT, (ratio.min(), ratio.max())


def test_a_request_beyond_the_pieces_is_named_and_the_five_kept(reference):
    """A slim body's calf asked 2.5 times the set's (the legs widen front to back only, each piece at most
    EXTRA_FACTOR_LIMIT): named, the five kept, and no further from the request than where it started."""
    start = synthesize_extra(reference, SLIM, {})[1]["calf"]
    _, measured, warnings, missed = synthesize_extra(reference, SLIM, {"calf": 82.0})
    assert [miss.key for miss in missed] == ["calf"] and missed[0].requested == 82.0
    assert missed[0].measured == measured["calf"] and "exact mode missed calf by" in warnings[-1]
    assert all(abs(measured[key] / value - 1.0) <= FIVE_RELATIVE for key, value in SLIM.items())
    assert abs(measured["calf"] - 82.0) <= abs(start - 82.0)


@pytest.mark.parametrize(
    "extra, amount",
    [
        ({"thigh": 90.0}, "thigh 90 cm >= Hi 83 cm by 7.00 cm"),
        ({"neck": 86.0}, "neck (Neck girth) must be 15-80 cm, got 86"),
        ({"thigh": 50.0, "calf": 51.0}, "calf 51 cm >= thigh 50 cm by 1.00 cm"),
        ({"calf": 84.0}, "calf 84 cm >= Hi 83 cm by 1.00 cm"),
        ({"upper_arm": 45.0}, "upper_arm 45 cm >= Br/2 42.485 cm by 2.52 cm"),
        ({"crotch_height": 90.0}, "crotch_height 90 cm >= 0.6 He 88.8 cm by 1.20 cm"),
        ({"crotch_height": 40.0}, "crotch_height 40 cm <= 0.3 He 44.4 cm by 4.40 cm"),
        ({"arm_length": 75.0}, "arm_length 75 cm >= 0.5 He 74 cm by 1.00 cm"),
        ({"neck": 10.0}, "neck (Neck girth) must be 15-80 cm, got 10"),
        ({"waist": 10.0}, "waist: not a measurement"),
    ],
)
def test_contradictions_are_refused_with_the_amount(reference, extra, amount):
    problems = extra_request_problems(SLIM, extra)
    assert problems and problems[0].startswith(amount), problems
    with pytest.raises(ExtraRequestError, match=amount.split()[0]):
        synthesize_extra(reference, SLIM, extra)
    assert extra_request_problems(SLIM, SLIM_EXTRA) == [] and extra_request_problems(HEAVY, HEAVY_EXTRA) == []


def test_a_neck_above_the_breast_is_refused():
    flat = dict(SLIM, Br=70.0)
    assert extra_request_problems(flat, {"neck": 72.0})[0] == (
        "neck 72 cm >= Br 70 cm by 2.00 cm: a neck cannot be larger than the breast"
    )


def test_longer_legs_and_arms_keep_the_fingers_on_the_hand(reference):
    """The arm is stretched along itself by an affine map, so pieces that touch keep touching: with the crotch
    height and the arm length asked 8 % over the set's (the five re-met every round), the fingers keep 0.89 of
    their overlap with the hand (each piece's own axes scaled by their share along the arm kept 0.6 of it, and
    opened them off the hand on longer requests: their skin fell apart there)."""
    from ellimann_addon.core.constants import TABLE_2_5
    from ellimann_addon.core.drape.fit_metrics import ellipsoid_signed_distance
    from ellimann_addon.core.geometry.ellipsoid import sample_surface

    def overlap(mannequin):
        fingers, hand = (mannequin.topology.index[name] for name in ("4.b Fingers.L", "4.a Hand.L"))
        arrays = (mannequin.rotation, mannequin.center, mannequin.semi_axes)
        points = sample_surface(*(a[fingers : fingers + 1] for a in arrays), 4000).reshape(-1, 3)
        return -ellipsoid_signed_distance(points, *(a[hand] for a in arrays)).min()

    start, measured, _, _ = synthesize_extra(reference, TABLE_2_5[0], {})
    longer = {key: 1.08 * measured[key] for key in ("crotch_height", "arm_length")}
    mannequin, _, _, missed = synthesize_extra(reference, TABLE_2_5[0], longer)
    assert not missed and overlap(start) > 0.004
    assert overlap(mannequin) > 0.8 * overlap(start)
