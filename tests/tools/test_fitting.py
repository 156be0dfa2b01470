"""The build tool's ellipsoid fits, on meshes whose answer is known."""

import numpy as np
import pytest

from devkit.toy import rotation_from_vector
from ellimann_addon.core.frames import is_rotation
from ellimann_addon.core.mesh import icosphere
from tools.bodies import vertex_areas
from tools.fitting import inscribed_ellipsoid, moments_ellipsoid, principal_frame

ROTATION = rotation_from_vector([0.3, -0.2, 0.5])
SEMI = np.array([0.05, 0.08, 0.12])


def ellipsoid_mesh(rotation=ROTATION, semi=SEMI, center=(0.1, -0.2, 0.9), subdivisions=4):
    vertices, faces = icosphere(subdivisions)
    return (vertices * semi) @ rotation.T + np.asarray(center), faces


@pytest.mark.parametrize("frame", ["main", "limb"])
def test_the_inscribed_fit_of_an_ellipsoid_mesh_is_that_ellipsoid(frame):
    vertices, faces = ellipsoid_mesh()
    areas = vertex_areas(vertices, faces)
    # one axis comes from the points, the roll about it from the reference (here a relabelled true frame)
    reference = ROTATION[:, [1, 2, 0]]
    rotation, center, semi, kept = inscribed_ellipsoid(vertices, areas, vertices, areas, reference,
                                                       inside_fraction=0.0, slack=0.0, frame=frame)
    assert is_rotation(rotation)
    assert np.allclose(np.abs(rotation.T @ reference), np.eye(3), atol=2e-3)
    assert np.allclose(center, (0.1, -0.2, 0.9), atol=2e-3)
    assert np.all(semi <= SEMI[[1, 2, 0]] * 1.001) and np.all(semi >= SEMI[[1, 2, 0]] * 0.95)
    local = (vertices - center) @ rotation / semi
    assert np.sqrt((local ** 2).sum(axis=1)).min() >= 1.0 - 1e-9  # no vertex inside


def test_slack_lets_vertices_in_only_that_deep():
    vertices, faces = ellipsoid_mesh()
    areas = vertex_areas(vertices, faces)
    rotation, center, semi, _ = inscribed_ellipsoid(vertices, areas, vertices, areas, inside_fraction=0.0,
                                                    slack=0.05)
    radius = np.sqrt((((vertices - center) @ rotation / semi) ** 2).sum(axis=1))
    assert radius.min() >= 0.95 - 1e-9 and radius.min() < 1.0


def test_a_fixed_frame_is_the_reference_and_the_box_caps_the_size():
    vertices, faces = ellipsoid_mesh(np.eye(3), np.array([0.1, 0.1, 0.1]), (0.0, 0.0, 0.0))
    areas = vertex_areas(vertices, faces)
    top = vertices[:, 2] > 0.05  # a cap: its box is short in z, so the ellipsoid must be too
    rotation, center, semi, kept = inscribed_ellipsoid(vertices[top], areas[top], vertices, areas, frame="fixed",
                                                       margin=0.0, inside_fraction=0.0)
    assert np.array_equal(rotation, np.eye(3)) and kept is None
    assert semi[2] <= 0.5 * (0.1 - vertices[top, 2].min()) + 1e-12
    assert center[2] - semi[2] >= vertices[top, 2].min() - 1e-12


def test_limb_frame_follows_the_limb_and_keeps_the_reference_roll():
    axis = np.array([0.3, 0.1, -1.0]) / np.linalg.norm([0.3, 0.1, -1.0])
    rng = np.random.default_rng(0)
    t = rng.uniform(-0.15, 0.15, 4000)
    angle = rng.uniform(0, 2 * np.pi, 4000)
    u = np.cross(axis, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(axis, u)
    radius = 0.04 + 0.1 * (t + 0.15)  # a tapered tube
    points = t[:, None] * axis + radius[:, None] * (np.cos(angle)[:, None] * u + np.sin(angle)[:, None] * v)
    rotation, _, kept = principal_frame(points, np.ones(len(points)), frame="limb")
    assert is_rotation(rotation)
    assert abs(rotation[:, kept] @ axis) > 0.999
    # roll from the world axes: another axis lies in the plane of the limb and a world axis
    in_world_plane = [abs(np.linalg.det(np.stack([rotation[:, i], rotation[:, kept], np.eye(3)[j]]))) < 1e-12
                      for i in range(3) if i != kept for j in range(3)]
    assert any(in_world_plane)


def test_match_picks_the_principal_axis_closest_to_the_other_body_s():
    vertices, faces = ellipsoid_mesh()
    areas = vertex_areas(vertices, faces)
    for column in range(3):
        rotation, _, kept = principal_frame(vertices, areas, match=ROTATION[:, column])
        assert abs(rotation[:, kept] @ ROTATION[:, column]) > 0.999


def test_moments_fit_of_a_sphere_is_the_sphere():
    vertices, faces = ellipsoid_mesh(np.eye(3), np.full(3, 0.07), (0.0, 0.0, 1.0), subdivisions=5)
    areas = vertex_areas(vertices, faces)
    _, center, semi, _ = moments_ellipsoid(vertices, areas)
    assert np.allclose(center, (0.0, 0.0, 1.0), atol=1e-9)
    assert semi == pytest.approx(np.full(3, 0.07), rel=1e-3)


def test_unknown_frame_is_refused():
    with pytest.raises(ValueError, match="frame is 'sideways'"):
        principal_frame(np.eye(3), np.ones(3), frame="sideways")
