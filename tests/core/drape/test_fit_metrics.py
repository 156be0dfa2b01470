import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from devkit.toy import rotation_from_vector
from ellimann_addon.core.drape import fit_metrics as fm
from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.geometry.cushion import cushion_mesh
from ellimann_addon.core.geometry.ellipsoid import contains
from ellimann_addon.core.geometry.mesh import icosphere

vectors = st.tuples(*[st.floats(-3.2, 3.2)] * 3)
sizes = st.tuples(*[st.floats(0.02, 0.4)] * 3)
points3 = st.tuples(*[st.floats(-0.8, 0.8)] * 3)


@settings(max_examples=100, deadline=None)
@given(vectors, points3, st.floats(0.01, 0.5))
def test_sphere_distance_is_radial(rv, p, r):
    c = np.array([0.1, -0.2, 0.3])
    d = fm.ellipsoid_signed_distance(np.array([p]) + c, rotation_from_vector(rv), c, (r, r, r))
    assert d[0] == pytest.approx(np.linalg.norm(p) - r, abs=1e-12)


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_points_on_an_axis_outside_are_at_the_vertex_distance(axis):
    a = np.array([0.3, 0.2, 0.1])
    s = np.array([0.31, 0.5, 2.0]) * a[axis] / 0.3 + a[axis]
    p = np.zeros((3, 3))
    p[:, axis] = s
    r = rotation_from_vector((0.4, -0.2, 0.9))
    c = np.array([1.0, 2.0, 3.0])
    d = fm.ellipsoid_signed_distance(p @ r.T + c, r, c, a)
    assert np.allclose(d, s - a[axis], atol=1e-12)


def test_inside_on_the_major_axis_matches_the_evolute_closed_form():
    # Ellipse x^2/a^2 + y^2/b^2 = 1 (c >= a makes the third axis irrelevant... use c between):
    # for |x0| < a - b^2/a on the major axis, the nearest points are off-axis at
    # distance b sqrt(1 - x0^2 / (a^2 - b^2)); beyond that the vertex is nearest: a - |x0|.
    a, b, c = 0.3, 0.1, 0.2
    x0 = np.array([0.0, 0.05, 0.15, 0.2, 0.25, 0.29])
    p = np.stack([x0, np.zeros_like(x0), np.zeros_like(x0)], axis=1)
    d = fm.ellipsoid_signed_distance(p, np.eye(3), np.zeros(3), (a, b, c))
    limit = a - b * b / a
    expected = np.where(x0 < limit, b * np.sqrt(np.clip(1 - x0**2 / (a * a - b * b), 0, None)), a - x0)
    assert np.allclose(-d, expected, atol=1e-12)


@settings(max_examples=100, deadline=None)
@given(vectors, sizes, st.lists(points3, min_size=1, max_size=20))
def test_nearest_point_is_on_the_surface_and_along_the_normal(rv, semi, pts):
    r, a = rotation_from_vector(rv), np.array(semi)
    c = np.array([0.05, 0.0, -0.1])
    p = np.array(pts)
    d, q = fm.ellipsoid_signed_distance(p, r, c, a, return_closest=True)
    local = (q - c) @ r
    assert np.allclose(np.sum((local / a) ** 2, axis=1), 1.0, atol=1e-9)
    assert np.allclose(np.linalg.norm(p - q, axis=1), np.abs(d), atol=1e-12)
    assert np.all((d < 0) == contains(r, c, a, p))
    # Lagrange condition: p - q is parallel to the surface normal M^-1 (q - c) at q.
    normal = (local / a**2) @ r.T
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    offset = p - q
    far = np.linalg.norm(offset, axis=1) > 1e-9
    cross = np.linalg.norm(np.cross(offset[far], normal[far]), axis=1) / np.linalg.norm(offset[far], axis=1)
    assert np.all(cross < 1e-6)


def test_agrees_with_dense_sampling():
    rng = np.random.default_rng(7)
    r = rotation_from_vector((0.3, 1.1, -0.4))
    a = np.array([0.25, 0.08, 0.15])
    c = np.zeros(3)
    p = rng.normal(size=(200, 3)) * 0.2
    d = fm.ellipsoid_signed_distance(p, r, c, a)
    u, v = np.meshgrid(np.linspace(0, np.pi, 800), np.linspace(0, 2 * np.pi, 1600), indexing="ij")
    surface = np.stack([np.sin(u) * np.cos(v), np.sin(u) * np.sin(v), np.cos(u)], -1).reshape(-1, 3) * a @ r.T
    brute = cKDTree(surface).query(p)[0]
    assert np.all(np.abs(d) <= brute + 1e-12)  # never farther than a real surface point
    assert np.allclose(np.abs(d), brute, atol=2e-4)  # sampling spacing ~0.3 mm


def test_degenerate_inside_points_on_symmetry_planes():
    a = np.array([0.1, 0.2, 0.3])
    # The centre: nearest is the end of the shortest axis. Equal short axes: any of them.
    assert fm.ellipsoid_signed_distance(np.zeros((1, 3)), np.eye(3), np.zeros(3), a)[0] == pytest.approx(-0.1)
    assert fm.ellipsoid_signed_distance(np.zeros((1, 3)), np.eye(3), np.zeros(3), (0.1, 0.1, 0.3))[0] == pytest.approx(
        -0.1
    )
    p = np.array([[0.0, 0.05, 0.02], [0.0, -0.1, 0.0], [0.0, 0.0, 0.1]])
    d, q = fm.ellipsoid_signed_distance(p, np.eye(3), np.zeros(3), a, return_closest=True)
    assert np.all(d < 0)
    assert np.allclose(np.sum((q / a) ** 2, axis=1), 1.0)
    # No better point among dense samples of the surface.
    s = icosphere(6)[0] * a
    brute = np.array([np.linalg.norm(s - x, axis=1).min() for x in p])
    assert np.all(-d <= brute + 1e-12)
    assert np.allclose(-d, brute, atol=1e-3)


def test_union_takes_the_nearest_ellipsoid():
    rot = np.stack([np.eye(3)] * 2)
    centers = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    semi = np.array([[0.1] * 3, [0.2] * 3])
    p = np.array([[0.5, 0, 0], [0.0, 0.3, 0], [1.0, 0.0, 0.0]])
    d, nearest = fm.union_signed_distance(p, rot, centers, semi)
    assert np.allclose(d, [0.3, 0.2, -0.2])
    assert nearest.tolist() == [1, 0, 1]


def unit_cube():
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float) * 0.5
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    faces = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    return v, faces


def box_distance(p, h=0.5):
    q = np.abs(p) - h
    return np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)


def test_point_triangle_distance_in_every_region():
    a, b, c = np.array([0.0, 0, 0]), np.array([1.0, 0, 0]), np.array([0.0, 1, 0])
    p = np.array(
        [
            [0.2, 0.2, 0.3],  # above the face: its height
            [0.5, -0.4, 0.0],  # beyond edge ab: distance to the edge
            [0.8, 0.8, 0.0],  # beyond edge bc: (0.8 + 0.8 - 1) / sqrt 2
            [-0.3, -0.4, 0.0],  # beyond vertex a
            [1.3, -0.4, 1.2],  # beyond vertex b, off the plane
        ]
    )
    q = fm.closest_points_on_triangles(p, a, b, c)
    d = np.linalg.norm(p - q, axis=1)
    assert np.allclose(d, [0.3, 0.4, 0.6 / np.sqrt(2), 0.5, 1.3], atol=1e-12)


def test_mesh_distance_on_a_cube_matches_the_box_sdf():
    v, f = unit_cube()
    rng = np.random.default_rng(1)
    p = np.concatenate([rng.uniform(-1.5, 1.5, (2000, 3)), rng.uniform(-0.49, 0.49, (200, 3))])
    d, face = fm.mesh_distance(p, v, f)
    assert np.allclose(d, box_distance(p), atol=1e-12)
    assert np.allclose(fm.convex_mesh_signed_distance(p, v, f), box_distance(p), atol=1e-12)
    # Points just off vertices and edges (where a face normal alone gives the wrong sign).
    corners = np.array(
        [[0.5001, 0.5001, 0.5001], [0.4999, 0.4999, 0.4999], [0.5001, 0.5001, 0.0], [0.4999, 0.4999, 0.2]]
    )
    assert np.allclose(fm.mesh_distance(corners, v, f)[0], box_distance(corners), atol=1e-12)


def test_mesh_distance_through_face_groups_is_the_nearest_of_every_triangle():
    """The grouped search (bounding spheres of groups, then of triangles) finds what trying every triangle
    finds, near a fine mesh (a torus: a surface with a hole, points inside it, near it and far from it) and
    with chunks of a few pairs (each point alone)."""
    u, w = np.meshgrid(np.linspace(0, 2 * np.pi, 60, endpoint=False), np.linspace(0, 2 * np.pi, 24, endpoint=False))
    v = np.stack([(0.3 + 0.1 * np.cos(w)) * np.cos(u), (0.3 + 0.1 * np.cos(w)) * np.sin(u), 0.1 * np.sin(w)], -1)
    v = v.reshape(-1, 3)
    i, j = np.meshgrid(np.arange(60), np.arange(24))
    a, b, c, d = (jj % 24 * 60 + ii % 60 for ii, jj in ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)))
    f = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    p = np.random.default_rng(3).normal(size=(300, 3)) * np.array([0.3, 0.3, 0.1])
    p = np.concatenate([p, [[0.0, 0.0, 0.0], [2.0, 1.0, -1.0]]])  # the hole's centre, far off
    t = v[f]
    every = np.linalg.norm(
        fm.closest_points_on_triangles(p[:, None], t[None, :, 0], t[None, :, 1], t[None, :, 2]) - p[:, None], axis=-1
    ).min(axis=1)
    ring = np.hypot(np.hypot(p[:, 0], p[:, 1]) - 0.3, p[:, 2]) - 0.1  # the smooth torus' signed distance
    for budget in (200_000, 1):
        d, face = fm.mesh_distance(p, v, f, pairs_per_chunk=budget)
        assert np.allclose(np.abs(d), every, atol=1e-12)
        assert np.array_equal(np.sign(d), np.sign(ring))  # no point lies within the facets' sag of the surface
        assert np.allclose(
            np.linalg.norm(fm.closest_points_on_triangles(p, *np.moveaxis(t[face], 1, 0)) - p, axis=1), every
        )


def test_mesh_distance_refuses_open_meshes_for_signs():
    v, f = unit_cube()
    with pytest.raises(ElliMannError, match="closed"):
        fm.mesh_distance(np.zeros((1, 3)), v, f[:-1])
    d, _ = fm.mesh_distance(np.array([[0.0, 0.0, 2.0]]), v, f[:-1], signed=False)
    assert d[0] == pytest.approx(1.5)


def test_convex_mesh_distance_agrees_with_the_general_one_on_a_cushion():
    e1 = (rotation_from_vector((0.2, 0.1, 0)), np.zeros(3), np.array([0.1, 0.06, 0.15]))
    e2 = (rotation_from_vector((0, 0.3, 0.2)), np.array([0.05, 0.0, -0.25]), np.array([0.05, 0.05, 0.12]))
    v, f = cushion_mesh(e1, e2, 3)
    p = np.random.default_rng(2).normal(size=(500, 3)) * 0.2
    general, _ = fm.mesh_distance(p, v, f)
    assert np.allclose(fm.convex_mesh_signed_distance(p, v, f), general, atol=1e-12)
    # The cutoff only ever replaces far values by a lower bound at or above the cutoff.
    cut = fm.convex_mesh_signed_distance(p, v, f, cutoff=0.05)
    assert np.all(cut[general <= 0.05] == pytest.approx(general[general <= 0.05]))
    assert np.all((cut >= 0.05) | (general <= 0.05)) and np.all(cut <= general + 1e-12)


def test_body_pieces_with_cushions_fill_the_bridge(toy):
    chest, belly = toy.topology.index["2.a Chest"], toy.topology.index["2.b Belly"]
    # A point beside the waist between the chest and belly ellipsoids' widest sections.
    mid = 0.5 * (toy.center[chest] + toy.center[belly])
    p = np.array([mid + np.array([0.16, 0.0, 0.0]), [0.0, 0.0, 3.0]])
    plain, names = fm.mannequin_signed_distance(p, toy)
    hull, hull_names = fm.mannequin_signed_distance(p, toy, cushions=True)
    assert hull_names[0] == "2.a Chest + 2.b Belly"
    assert hull[0] <= plain[0] + 1e-12  # the hull holds both ellipsoids
    assert hull[1] == pytest.approx(plain[1])  # far above the head: the head is nearest either way
    assert names[1] == hull_names[1] == "1.a Head"


def test_fit_statistics():
    stats = fm.fit_statistics([-0.01, 0.0, 0.002, 0.02, 0.05], contact=0.005)
    assert stats["count"] == 5
    assert stats["penetrating"] == 1 and stats["max_depth"] == pytest.approx(0.01)
    assert stats["touching_fraction"] == pytest.approx(2 / 5)
    assert stats["min"] == -0.01 and stats["max"] == 0.05 and stats["median"] == 0.002
    with pytest.raises(ElliMannError, match="distance"):
        fm.fit_statistics([])
    with pytest.raises(ElliMannError, match="distance"):
        fm.fit_statistics([0.0, np.nan])
