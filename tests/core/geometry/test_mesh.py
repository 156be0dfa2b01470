"""core.geometry.mesh's edge and hull helpers: unique_rows is np.unique(axis=0) on edges, the closed-manifold check
and the open edges find what a hole, a flipped or a doubled face does, and the 2-D hull holds every point with
strict left turns at its corners."""

import numpy as np
import pytest

from ellimann_addon.core.geometry.mesh import (
    boundary_edges,
    convex_hull_2d,
    euler_characteristic,
    icosphere,
    is_closed_manifold,
    unique_rows,
)


@pytest.mark.parametrize(
    "pairs",
    [
        np.random.default_rng(1).integers(0, 40, size=(500, 2)),
        np.random.default_rng(2).integers(0, 4, size=(30, 2)).astype(np.int32),
        np.random.default_rng(3).integers(0, 9, size=(50, 2)).astype(np.uint32),
        np.array([[3, -1], [0, 2], [3, -1]]),  # negative: numpy's own way
        np.zeros((0, 2), np.int64),
    ],
    ids=["int64", "int32", "uint32", "negative", "empty"],
)
def test_unique_rows_is_numpys_unique_along_rows(pairs):
    rows, inverse, counts = unique_rows(pairs, return_inverse=True, return_counts=True)
    expected, expected_inverse, expected_counts = np.unique(pairs, axis=0, return_inverse=True, return_counts=True)
    assert rows.dtype == pairs.dtype and np.array_equal(rows, expected)
    assert np.array_equal(inverse, expected_inverse.reshape(-1)) and np.array_equal(counts, expected_counts)
    assert np.array_equal(unique_rows(pairs), expected)


def test_a_closed_mesh_and_what_opens_flips_or_doubles_a_face():
    vertices, faces = icosphere(2)
    assert is_closed_manifold(faces) and euler_characteristic(vertices, faces) == 2
    assert len(boundary_edges(faces)) == 0
    holed = faces[1:]
    assert not is_closed_manifold(holed)
    assert {tuple(e) for e in boundary_edges(holed)} == {tuple(sorted(e)) for e in faces[0][[[0, 1], [1, 2], [2, 0]]]}
    flipped = faces.copy()
    flipped[5] = flipped[5][::-1]
    assert not is_closed_manifold(flipped)
    assert not is_closed_manifold(np.concatenate([faces, faces[:1]]))
    two = np.concatenate([faces, faces + len(vertices)])  # two spheres apart: each closed
    assert is_closed_manifold(two) and is_closed_manifold(np.zeros((0, 3), int))


def test_the_hull_of_a_square_is_its_corners_counter_clockwise_from_the_lowest():
    inside = np.random.default_rng(4).uniform(0.1, 0.9, size=(200, 2))
    on_edges = np.array([[0.5, 0.0], [1.0, 0.5], [0.5, 1.0], [0.0, 0.25], [0.0, 0.0]])  # collinear, and a repeat
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    hull = convex_hull_2d(np.concatenate([inside, on_edges, corners[::-1]]))
    assert np.array_equal(hull, corners)


@pytest.mark.parametrize("seed", range(5))
def test_the_hull_holds_every_point_and_turns_left_at_each_corner(seed):
    points = np.random.default_rng(seed).normal(size=(300, 2))
    hull = convex_hull_2d(points)
    assert {tuple(p) for p in hull} <= {tuple(p) for p in points}
    edges = np.roll(hull, -1, axis=0) - hull
    turns = edges[:, 0] * np.roll(edges, -1, axis=0)[:, 1] - edges[:, 1] * np.roll(edges, -1, axis=0)[:, 0]
    assert np.all(turns > 0.0)  # counter-clockwise, no collinear corner
    to_points = points[None] - hull[:, None]  # (h, n, 2): every point on the inner side of every edge
    side = edges[:, None, 0] * to_points[..., 1] - edges[:, None, 1] * to_points[..., 0]
    assert side.min() >= -1e-12
    assert len(convex_hull_2d(points[:2])) == 2 and len(convex_hull_2d(np.zeros((3, 2)))) == 1
