"""The fill metrics of the build tool (tools/shipped/coverage.py), on bodies and mannequins whose answer is known."""

import numpy as np
import pytest

from devkit.toy import rotation_from_vector
from ellimann_addon.core.geometry.mesh import icosphere
from ellimann_addon.core.geometry.mesh import volume as mesh_volume
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.topology import Part, Topology
from tools.shipped.coverage import BodyVolume, chain_gaps, fill_metrics, occupancy, report, separation

RADIUS = 0.1


def sphere(radius=RADIUS, center=(0.0, 0.0, 0.0), subdivisions=5):
    vertices, faces = icosphere(subdivisions)
    return vertices * radius + np.asarray(center), faces


def mannequin(*parts):
    """A mannequin of (name, centre, semi-axes, partner) parts, central, with world-aligned frames."""
    topology = Topology([Part(name, "C", "body", True, ("He",), partner) for name, _, _, partner in parts])
    rotation = np.tile(np.eye(3), (len(parts), 1, 1))
    center = np.array([c for _, c, _, _ in parts], dtype=float)
    semi = np.array([d for _, _, d, _ in parts], dtype=float)
    return Mannequin(topology, rotation, center, semi)


@pytest.fixture(scope="module")
def ball():
    vertices, faces = sphere()
    body = BodyVolume(vertices, faces)
    return body, body.grid(0.004), mesh_volume(vertices, faces)


def test_the_grid_inside_a_closed_mesh_has_its_volume(ball):
    body, grid, volume = ball
    assert np.count_nonzero(grid.inside) * grid.spacing**3 == pytest.approx(volume, rel=0.01)


def test_inside_and_distance_of_points_near_a_sphere(ball):
    body, _, _ = ball
    rng = np.random.default_rng(0)
    direction = rng.normal(size=(2000, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    radius = rng.uniform(0.5, 1.5, 2000) * RADIUS
    points = direction * radius[:, None]
    clear = np.abs(radius - RADIUS) > 0.002  # the mesh is a little inside the true sphere
    assert np.array_equal(body.contains(points)[clear], (radius < RADIUS)[clear])
    distance, nearest = body.distance(points)
    assert np.allclose(distance, np.abs(radius - RADIUS), atol=5e-4)
    assert np.all(np.linalg.norm(body.vertices[nearest] - points, axis=1) >= distance - 1e-12)


def test_a_part_slightly_larger_than_the_body_covers_it_and_reaches_out_by_the_difference(ball):
    body, grid, _ = ball
    grown = RADIUS + 0.005
    fill = fill_metrics(body, grid, mannequin(("1.a Ball", (0, 0, 0), (grown,) * 3, "")))["ellipsoids"]
    assert fill["coverage"] > 0.999
    assert fill["excess"] == pytest.approx(1.0 - (RADIUS / grown) ** 3, abs=0.01)
    assert fill["depth"] == pytest.approx(0.005, abs=5e-4) and fill["deepest"] == "1.a Ball"
    half = fill_metrics(body, grid, mannequin(("1.a Ball", (0, 0, 0), (RADIUS, RADIUS, RADIUS / 2), "")))
    assert half["ellipsoids"]["coverage"] == pytest.approx(0.5, abs=0.01)
    assert half["ellipsoids"]["depth"] < 5e-4


def test_cavity_walls_leave_their_points_out_of_the_depth_and_the_excess(ball):
    body, grid, _ = ball
    grown = mannequin(("1.a Ball", (0, 0, 0), (RADIUS + 0.005,) * 3, ""))
    cavity = np.ones(len(body.vertices), dtype=bool)
    fill = fill_metrics(body, grid, grown, cavity)["ellipsoids"]
    assert fill["depth"] == 0.0 and fill["excess"] == 0.0 and fill["coverage"] > 0.999
    # the walls of the upper half only: the shell above the equator is no excess, the shell below is
    upper = body.vertices[:, 2] > 0.0
    shell = 1.0 - (RADIUS / (RADIUS + 0.005)) ** 3
    assert fill_metrics(body, grid, grown, upper)["ellipsoids"]["excess"] == pytest.approx(shell / 2, abs=0.01)


def test_a_cushion_occupies_its_hull_a_capsule():
    vertices, faces = sphere(0.3, subdivisions=3)
    body = BodyVolume(vertices, faces)
    grid = body.grid(0.004)
    r, half = 0.04, 0.1
    capsule = mannequin(("1.a End", (-half, 0, 0), (r,) * 3, "1.b End"), ("1.b End", (half, 0, 0), (r,) * 3, "1.a End"))
    cell = grid.spacing**3
    expected = np.pi * r**2 * 2 * half + 4.0 / 3.0 * np.pi * r**3
    assert np.count_nonzero(occupancy(grid, capsule, cushions=True)) * cell == pytest.approx(expected, rel=0.02)
    assert np.count_nonzero(occupancy(grid, capsule)) * cell == pytest.approx(8.0 / 3.0 * np.pi * r**3, rel=0.02)


def test_separation_is_the_distance_between_hulls():
    far = mannequin(
        ("1.a A", (0, 0, 0), (0.05,) * 3, ""),
        ("2.a B", (0.2, 0, 0), (0.03,) * 3, ""),
        ("3.a C", (0.0, 0.3, 0), (0.05, 0.05, 0.05), ""),
    )
    assert separation(far, [0], [1]) == pytest.approx(0.2 - 0.08, abs=1e-6)
    # a capsule from A to C and B: the distance from B's centre to the segment, less both radii
    assert separation(far, [0, 2], [1]) == pytest.approx(0.2 - 0.08, abs=1e-6)
    turned = far.copy(rotation=np.stack([rotation_from_vector([0.3, 0.2, 0.1])] * 3))
    assert separation(turned, [0], [1]) == pytest.approx(0.12, abs=1e-6)  # spheres: frames do not matter
    near = mannequin(("1.a A", (0, 0, 0), (0.05,) * 3, ""), ("2.a B", (0.07, 0, 0), (0.03,) * 3, ""))
    assert separation(near, [0], [1]) == 0.0
    flat = mannequin(("1.a A", (0, 0, 0), (0.1, 0.01, 0.01), ""), ("2.a B", (0, 0.05, 0), (0.01,) * 3, ""))
    assert separation(flat, [0], [1]) == pytest.approx(0.03, abs=1e-6)


def test_chain_gaps_follow_the_links_and_cushions_close_them():
    # thigh-knee and calf-ankle cushions of a leg; the knee and the calf leave a 2 cm gap
    parts = [
        ("5.a Thigh", (0, 0, 0.6), (0.06, 0.06, 0.12), "5.b Knee"),
        ("5.b Knee", (0, 0, 0.3), (0.04,) * 3, "5.a Thigh"),
        ("6.a Calf", (0, 0, 0.18), (0.05, 0.05, 0.06), "6.b Ankle"),
        ("6.b Ankle", (0, 0, 0.1), (0.03,) * 3, "6.a Calf"),
    ]
    leg = mannequin(*parts)
    gaps = chain_gaps(leg)["leg"]
    assert gaps == pytest.approx([0.6 - 0.12 - 0.34, 0.26 - 0.24, 0.0], abs=1e-6)
    assert chain_gaps(leg, cushions=True)["leg"] == pytest.approx([0.0, 0.02, 0.0], abs=1e-6)


def test_report_has_both_mannequins_and_every_chain(ball):
    body, _, _ = ball
    result = report(mannequin(("1.a Ball", (0, 0, 0), (RADIUS,) * 3, "")), body.vertices, body.faces, spacing=0.01)
    assert set(result) == {"ellipsoids", "cushions"}
    assert {"coverage", "excess", "depth", "deepest", "gaps"} <= set(result["cushions"])
