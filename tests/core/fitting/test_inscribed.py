"""The reference builder's ellipsoid fits (core/fitting/inscribed.py) and body helpers
(core/fitting/body_mesh.py), on meshes whose answer is known."""

import numpy as np
import pytest

from devkit.toy import rotation_from_vector
from ellimann_addon.core.fitting.body_mesh import hidden_vertices, surface_walls, vertex_areas, vertex_normals
from ellimann_addon.core.fitting.inscribed import _grow, cell_share, hull_surface, inscribed_ellipsoid, principal_frame
from ellimann_addon.core.fitting.mannequin_fit import _dilated
from ellimann_addon.core.geometry.ellipsoid import fibonacci_sphere, to_frame
from ellimann_addon.core.geometry.frames import is_rotation
from ellimann_addon.core.geometry.mesh import icosphere

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
    rotation, center, semi, kept = inscribed_ellipsoid(
        vertices, areas, vertices, areas, reference, inside_fraction=0.0, frame=frame
    )
    assert is_rotation(rotation)
    assert np.allclose(np.abs(rotation.T @ reference), np.eye(3), atol=2e-3)
    assert np.allclose(center, (0.1, -0.2, 0.9), atol=2e-3)
    assert np.all(semi <= SEMI[[1, 2, 0]] * 1.001) and np.all(semi >= SEMI[[1, 2, 0]] * 0.95)
    local = (vertices - center) @ rotation / semi
    assert np.sqrt((local**2).sum(axis=1)).min() >= 1.0 - 1e-9  # no vertex inside


def test_obstacles_moved_out_let_the_ellipsoid_reach_that_far():
    # the build tool moves the body's vertices out along their normals by the allowed depth
    vertices, faces = ellipsoid_mesh(np.eye(3), np.full(3, 0.1), (0.0, 0.0, 0.0))
    areas = vertex_areas(vertices, faces)
    normals = vertex_normals(vertices, faces)
    assert np.allclose(normals, vertices / np.linalg.norm(vertices, axis=1, keepdims=True), atol=1e-2)
    walls = vertices + 0.005 * normals
    _, center, semi, _ = inscribed_ellipsoid(vertices, areas, walls, areas, frame="fixed", inside_fraction=0.0)
    radius = np.linalg.norm(walls, axis=1).min()
    assert np.all(semi <= radius + 1e-9) and np.all(semi >= 0.0985 + 0.005 * 0.95)
    assert np.allclose(center, 0.0, atol=1e-3)


@pytest.mark.parametrize("allowed, reach", [(0.0, 1.0), (0.5, 1.0), (1.5, 2.0), (2.5, 3.0), (3.5, 4.0)])
def test_points_of_the_allowed_area_may_end_inside_and_the_next_one_stops_the_growth(allowed, reach):
    # points on the x axis at 1, 2 and 3 (area 1 each): with ``allowed`` units of area allowed inside, the
    # floor(allowed) nearest end inside and the next stops the x semi-axis on it; y and z grow to their limit
    local = np.array([[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
    semi = _grow(local, np.ones(3), np.array([4.0, 0.5, 0.5]), np.full(3, 0.1), allowed)
    assert semi[0] == pytest.approx(reach, rel=1e-9) and semi[0] <= reach
    assert np.allclose(semi[1:], 0.5)


def test_a_fixed_frame_is_the_reference_and_the_box_caps_the_size():
    vertices, faces = ellipsoid_mesh(np.eye(3), np.array([0.1, 0.1, 0.1]), (0.0, 0.0, 0.0))
    areas = vertex_areas(vertices, faces)
    top = vertices[:, 2] > 0.05  # a cap: its box is short in z, so the ellipsoid must be too
    rotation, center, semi, kept = inscribed_ellipsoid(
        vertices[top], areas[top], vertices, areas, frame="fixed", margin=0.0, inside_fraction=0.0
    )
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
    in_world_plane = [
        abs(np.linalg.det(np.stack([rotation[:, i], rotation[:, kept], np.eye(3)[j]]))) < 1e-12
        for i in range(3)
        if i != kept
        for j in range(3)
    ]
    assert any(in_world_plane)


def test_match_picks_the_principal_axis_closest_to_the_other_body_s():
    vertices, faces = ellipsoid_mesh()
    areas = vertex_areas(vertices, faces)
    for column in range(3):
        rotation, _, kept = principal_frame(vertices, areas, match=ROTATION[:, column])
        assert abs(rotation[:, kept] @ ROTATION[:, column]) > 0.999


def test_floor_and_ceiling_bound_the_ellipsoid_s_height_exactly():
    vertices, faces = ellipsoid_mesh()  # tilted: the bound is on the world-z extent, not a local axis
    areas = vertex_areas(vertices, faces)
    rotation, center, semi, _ = inscribed_ellipsoid(
        vertices, areas, vertices, areas, inside_fraction=0.0, floor=0.86, ceiling=0.95
    )
    half_height = np.sqrt(np.sum((rotation[2] * semi) ** 2))
    assert center[2] - half_height >= 0.86 - 1e-9 and center[2] + half_height <= 0.95 + 1e-9
    assert 0.95 - 0.86 - 2.0 * half_height < 0.01  # and it uses the height it has


def test_level_fixes_the_centre_height():
    vertices, faces = ellipsoid_mesh()
    areas = vertex_areas(vertices, faces)
    _, center, _, _ = inscribed_ellipsoid(vertices, areas, vertices, areas, inside_fraction=0.0, level=0.93)
    assert center[2] == pytest.approx(0.93, abs=1e-12)


def tube(radius, half_length=0.2, count=6000):
    """Points on the side of a tube along x whose radius is ``radius(x)``: a limb, open at its ends
    (which join the rest of a body)."""
    rng = np.random.default_rng(1)
    x = rng.uniform(-half_length, half_length, count)
    angle = rng.uniform(0.0, 2.0 * np.pi, count)
    r = radius(x)
    return np.stack([x, r * np.cos(angle), r * np.sin(angle)], axis=1)


def test_span_reaches_from_one_end_of_the_limb_to_the_other():
    points = tube(lambda x: 0.055 - 0.1 * x)  # tapering from 7.5 cm to 3.5 cm
    weights = np.ones(len(points))
    fit = dict(frame="limb", inside_fraction=0.0, margin=0.0)
    rotation, center, semi, kept = inscribed_ellipsoid(points, weights, points, weights, span=True, **fit)
    assert abs(rotation[:, kept] @ [1.0, 0.0, 0.0]) > 0.99
    assert semi[kept] == pytest.approx(np.ptp(points @ rotation[:, kept]) / 2.0, rel=1e-6)
    assert abs(center[0]) < 1e-3
    # the largest ellipsoid settles in the thick end instead, and is shorter
    _, plain_center, plain, _ = inscribed_ellipsoid(points, weights, points, weights, **fit)
    assert plain[kept] < 0.9 * semi[kept] and plain_center[0] < -0.02


def test_fill_weights_draw_the_part_to_the_volume_that_counts():
    points = tube(lambda x: np.full_like(x, 0.05), half_length=0.3)
    weights = np.ones(len(points))
    grid = np.stack(
        np.meshgrid(
            np.linspace(-0.3, 0.3, 61), np.linspace(-0.05, 0.05, 11), np.linspace(-0.05, 0.05, 11), indexing="ij"
        ),
        axis=-1,
    ).reshape(-1, 3)
    inside = grid[np.hypot(grid[:, 1], grid[:, 2]) < 0.05]
    fit = dict(frame="fixed", inside_fraction=0.0, margin=0.0, fill=inside, fill_spacing=0.01)
    _, even, _, _ = inscribed_ellipsoid(points, weights, points, weights, **fit)
    _, right, _, _ = inscribed_ellipsoid(
        points, weights, points, weights, **fit, fill_weight=(inside[:, 0] > 0.1).astype(float)
    )
    assert abs(even[0]) < 0.02 and right[0] > 0.1
    # a central part keeps its centre in the middle across world x, whatever draws it aside
    _, middle, _, _ = inscribed_ellipsoid(
        points, weights, points, weights, **fit, fill_weight=(inside[:, 0] > 0.1).astype(float), midline=True
    )
    box_middle = 0.5 * (points[:, 0].min() + points[:, 0].max())
    assert middle[0] == pytest.approx(box_middle, abs=1e-12)


def test_a_cost_for_the_outside_picks_an_ellipsoid_that_reaches_out_less():
    # a box body whose surface a part may overstep by 10 mm: free, the part fills the box and that margin all round;
    # paying for the cells outside, it settles for less of both, and it is what it pays for that it keeps lowest
    rng = np.random.default_rng(0)
    half, depth, spacing = np.array([0.1, 0.05, 0.05]), 0.01, 0.01
    surface = rng.uniform(-1.0, 1.0, (6000, 3))
    face = rng.integers(0, 3, len(surface))
    surface[np.arange(len(surface)), face] = np.sign(surface[np.arange(len(surface)), face])
    points, walls = surface * half, surface * (half + depth)
    axis = np.arange(-0.13, 0.13, spacing)
    grid = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    inside = np.all(np.abs(grid) < half, axis=1)
    cells = np.concatenate([grid[inside], grid[~inside & np.all(np.abs(grid) < half + 0.02, axis=1)]])
    body = int(inside.sum())
    fit = dict(frame="fixed", inside_fraction=0.0, margin=0.3, fill=cells, fill_spacing=spacing)
    covered = {}
    for cost in (0.0, 3.0):
        weight = np.where(np.arange(len(cells)) < body, 1.0, -cost)
        rotation, center, semi, _ = inscribed_ellipsoid(
            points, np.ones(len(points)), walls, np.ones(len(walls)), np.eye(3), fill_weight=weight, **fit
        )
        share = cell_share(to_frame(cells, center, rotation), semi, spacing)
        covered[cost] = share[:body].sum(), share[body:].sum()
        if cost == 0.0:
            assert semi == pytest.approx(half + depth, rel=0.01)
    (free_in, free_out), (paid_in, paid_out) = covered[0.0], covered[3.0]
    assert paid_out < 0.5 * free_out and paid_in > 0.8 * free_in
    assert paid_in - 3.0 * paid_out > free_in - 3.0 * free_out


def test_hull_surface_samples_the_hull_and_its_area():
    corners = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
    inner = np.random.default_rng(2).uniform(-0.9, 0.9, (50, 3))
    points, areas = hull_surface(np.concatenate([corners, inner]), depth=0.0, spacing=0.2)
    assert np.allclose(np.abs(points).max(axis=1), 1.0)  # on the cube's faces
    assert areas.sum() == pytest.approx(24.0)
    moved, _ = hull_surface(corners, depth=0.1, spacing=0.2)
    assert np.allclose(np.abs(moved).max(axis=1), 1.1)


def _icosahedron(radius=0.1):
    vertices, faces = icosphere(0)
    return radius * vertices, faces


def _outside_planes(vertices, faces, points):
    """How far (m) each point lies outside a convex mesh: the largest signed distance to its faces' planes."""
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    normal = np.cross(b - a, c - a)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    return np.max(points @ normal.T - np.einsum("fi,fi->f", normal, a), axis=1)


def test_surface_walls_without_a_spacing_are_the_vertices_moved_out():
    vertices, faces = _icosahedron()
    areas, normals = vertex_areas(vertices, faces), vertex_normals(vertices, faces)
    kept = np.arange(1, 12)
    points, weights = surface_walls(vertices, faces, normals, areas, kept, 0.004)
    assert np.array_equal(points, vertices[kept] + 0.004 * normals[kept]) and np.array_equal(weights, areas[kept])
    # a spacing longer than every edge divides nothing: the same bits
    same = surface_walls(vertices, faces, normals, areas, kept, 0.004, spacing=0.5)
    assert np.array_equal(same[0], points) and np.array_equal(same[1], weights)


def test_surface_walls_cover_every_kept_triangle_and_keep_its_area():
    vertices, faces = _icosahedron()  # edges 105 mm
    areas, normals = vertex_areas(vertices, faces), vertex_normals(vertices, faces)
    kept = np.arange(1, 12)  # vertex 0 is a cavity wall: its five triangles are no walls, as before
    points, weights = surface_walls(vertices, faces, normals, areas, kept, 0.0, spacing=0.01)
    assert weights.sum() == pytest.approx(areas[kept].sum(), rel=1e-12)
    assert np.all(weights > 0.0)
    assert np.abs(_outside_planes(vertices, faces, points)).max() < 1e-12  # on the surface (inside: <= 0, on: 0)
    # every point of a kept triangle lies within the spacing of a wall point; of vertex 0's, not
    rng = np.random.default_rng(3)
    u, v = rng.uniform(size=(2, 2000))
    u, v = np.where(u + v > 1.0, 1.0 - u, u), np.where(u + v > 1.0, 1.0 - v, v)
    for face in faces:
        a, b, c = vertices[face]
        samples = a + u[:, None] * (b - a) + v[:, None] * (c - a)
        nearest = np.linalg.norm(samples[:, None, :] - points[None], axis=2).min(axis=1)
        assert (nearest.max() <= 0.01) == (0 not in face)


def test_surface_walls_of_a_fold_stay_on_the_surface():
    # a long triangle whose corners' normals cancel half way (a fold of the mesh): no point of it is lost or NaN
    vertices = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0]])
    faces = np.array([[0, 1, 2]])
    normals = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 0.0, 1.0]])
    points, weights = surface_walls(vertices, faces, normals, vertex_areas(vertices, faces), np.arange(3), 0.004, 0.02)
    assert np.all(np.isfinite(points)) and weights.sum() == pytest.approx(0.005)
    halfway = np.all(np.isclose(points, [0.05, 0.0, 0.0]), axis=1)
    assert halfway.sum() == 1  # where the normals cancel the point is not moved


def test_wall_points_keep_a_part_from_slipping_out_between_the_vertices():
    # a sphere fitted in a coarse icosahedron: its 12 vertices alone let it grow to them, 20 mm out of the faces;
    # with points 5 mm apart on the faces it stays within a sagitta of them
    vertices, faces = _icosahedron()
    areas, normals = vertex_areas(vertices, faces), vertex_normals(vertices, faces)
    surface = fibonacci_sphere(4000)
    reach = {}
    for spacing in (None, 0.005):
        walls, wall_areas = surface_walls(vertices, faces, normals, areas, np.arange(12), 0.0, spacing)
        rotation, center, semi, _ = inscribed_ellipsoid(
            vertices, areas, walls, wall_areas, np.eye(3), frame="fixed", inside_fraction=0.0, margin=0.5
        )
        reach[spacing] = _outside_planes(vertices, faces, center + (surface * semi) @ rotation.T).max()
    assert reach[None] > 0.015
    assert reach[0.005] < 0.001


def test_hidden_vertices_are_those_that_cannot_see_out():
    # a sphere inside a sphere: the inner one's outward rays meet the outer one, the outer's escape
    outer, outer_faces = ellipsoid_mesh(np.eye(3), np.full(3, 1.0), (0.0, 0.0, 0.0), subdivisions=3)
    # (turned, so that no ray runs exactly through a vertex of the outer one)
    inner, inner_faces = ellipsoid_mesh(ROTATION, np.full(3, 0.5), (0.0, 0.0, 0.0), subdivisions=2)
    vertices = np.concatenate([outer, inner])
    faces = np.concatenate([outer_faces, inner_faces + len(outer)])
    normals = vertex_normals(vertices, faces)
    hidden = hidden_vertices(vertices, faces, normals, np.arange(len(vertices)), reach=0.6, cell=0.1)
    assert not hidden[: len(outer)].any() and hidden[len(outer) :].all()
    # beyond reach nothing is met
    assert not hidden_vertices(vertices, faces, normals, np.arange(len(vertices)), reach=0.4, cell=0.1).any()


def test_unknown_frame_is_refused():
    with pytest.raises(ValueError, match="frame is 'sideways'"):
        principal_frame(np.eye(3), np.ones(3), frame="sideways")


def test_a_grid_mask_dilated_holds_every_cell_within_that_many_cells_every_way():
    mask = np.random.default_rng(4).uniform(size=(9, 8, 7)) > 0.97
    grown = _dilated(mask, 2)
    index = np.argwhere(np.ones(mask.shape, dtype=bool))
    chebyshev = np.abs(index[:, None, :] - np.argwhere(mask)[None]).max(axis=2).min(axis=1)
    assert np.array_equal(grown.ravel(), chebyshev <= 2) and mask.sum() > 3
