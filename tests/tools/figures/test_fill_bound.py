"""The greedy fill bound (tools/figures/fill_bound.py) on a sphere, whose answer is known."""

import numpy as np
import pytest

from tests.tools.shipped.test_coverage import RADIUS, mannequin, sphere
from tools.figures.fill_bound import fill_curve
from tools.shipped.coverage import BodyVolume, fill_metrics


@pytest.fixture(scope="module")
def body():
    return BodyVolume(*sphere())


def small_piece():
    return mannequin(("1.a Core", (0, 0, 0), (0.02,) * 3, "")).copy(section_fractions={})


def test_the_first_ball_in_a_sphere_is_the_deepest_and_fills_its_share(body):
    grid = body.grid(0.006)
    curve, balls = fill_curve(body, grid, small_piece(), 0.0, reach=RADIUS, most=1)
    assert curve[0][0] == pytest.approx(fill_metrics(body, grid, small_piece())["ellipsoids"]["coverage"])
    (centre, radius), (coverage, excess) = balls[0], curve[1]
    assert np.linalg.norm(centre) <= 0.5 * np.sqrt(3.0) * grid.spacing  # the cell nearest the sphere's centre
    assert radius == pytest.approx(RADIUS - np.linalg.norm(centre), abs=0.001)  # touching the surface
    assert coverage == pytest.approx((radius / RADIUS) ** 3, abs=0.02) and excess < 0.01


def test_balls_fill_more_with_each_stop_at_the_target_and_keep_clear_of_the_sections(body):
    grid = body.grid(0.006)
    cut = small_piece().copy(section_fractions={"Br": 0.5})  # a section through the sphere's middle
    curve, balls = fill_curve(body, grid, cut, 0.0, clearance=0.05, target=0.6)
    coverage = [c for c, _ in curve]
    assert np.all(np.diff(coverage) > 0.0) and coverage[-1] >= 0.6 > coverage[-2]
    band = 0.05 * 2 * RADIUS
    for centre, radius in balls:
        assert centre[2] - radius >= band - grid.spacing or centre[2] + radius <= -band + grid.spacing
    assert max(excess for _, excess in curve) < 0.01  # touching the surface, not reaching past it


def test_a_ball_pays_for_the_outside_it_fills(body):
    # the deepest ball reaching 2 cm out would spill 42 % of itself; one that fills less but spills less is worth more
    curve, _ = fill_curve(body, body.grid(0.01), small_piece(), 0.02, reach=RADIUS, most=1)
    assert curve[1][1] < 0.25
