import numpy as np
import pytest
from scipy.spatial import ConvexHull

from devkit import synthetic
from devkit.toy import rotation_from_vector
from ellimann_addon.core.constants import REFERENCE_MEASUREMENTS
from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.geometry import cushion, mesh
from ellimann_addon.core.geometry.ellipsoid import contains, support
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER
from ellimann_addon.core.synthesis.synthesize import synthesize


def check_convex_closed(v, f):
    assert mesh.is_closed_manifold(f)
    assert mesh.euler_characteristic(v, f) == 2
    assert mesh.volume(v, f) > 0  # outward winding
    assert mesh.convexity_defect(v, f) <= 1e-12 * np.ptp(v, axis=0).max()


@pytest.mark.parametrize("distance", [0.0, 0.1, 0.3, 0.8])
def test_two_equal_spheres_give_a_capsule(distance):
    r = 0.1
    v, f = cushion.cushion_mesh((np.eye(3), (0, 0, 0), (r, r, r)), (np.eye(3), (0, 0, distance), (r, r, r)))
    check_convex_closed(v, f)
    exact = np.pi * r * r * distance + 4 / 3 * np.pi * r**3
    assert mesh.volume(v, f) == pytest.approx(exact, rel=0.01)
    assert mesh.volume(v, f) < exact  # inscribed


def test_resolution_converges():
    e1 = (np.eye(3), (0, 0, 0), (0.1, 0.1, 0.1))
    e2 = (np.eye(3), (0.3, 0, 0), (0.1, 0.1, 0.1))
    exact = np.pi * 0.01 * 0.3 + 4 / 3 * np.pi * 0.001
    errors = [abs(mesh.volume(*cushion.cushion_mesh(e1, e2, s)) / exact - 1) for s in (2, 3, 4)]
    assert errors[0] > errors[1] > errors[2]


def random_pair(rng, lo=0.02):
    def make():
        return rotation_from_vector(rng.normal(size=3) * 2), rng.normal(size=3) * 0.1, rng.uniform(lo, 0.2, 3)

    return make(), make()


@pytest.mark.parametrize("seed", range(12))
def test_random_pairs_are_the_convex_hull(seed):
    e1, e2 = random_pair(np.random.default_rng(seed), lo=0.01)
    v, f = cushion.cushion_mesh(e1, e2, 3)
    check_convex_closed(v, f)
    assert mesh.volume(v, f) == pytest.approx(ConvexHull(v).volume, rel=1e-9)
    # Every vertex lies on one of the two ellipsoids and the mesh contains both centres.
    on_surface = [np.abs(np.sum(((v - c) @ r / d) ** 2, axis=1) - 1) < 1e-9 for r, c, d in (e1, e2)]
    assert np.all(on_surface[0] | on_surface[1])
    # Its support equals that of the union in every vertex normal direction (up to resolution).
    n = np.random.default_rng(seed).normal(size=(50, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    union = np.maximum(support(*e1, n), support(*e2, n))
    assert np.all((v @ n.T).max(axis=0) <= union + 1e-12)
    assert np.all((v @ n.T).max(axis=0) >= union - 0.01 * 0.2)


@pytest.mark.parametrize("subdivisions", [1, 2, 3, 4])
def test_batched_hulls_agree_with_scipys_convex_hull_of_the_same_vertices(subdivisions):
    rng = np.random.default_rng(100 + subdivisions)
    pairs = [random_pair(rng, lo=0.01) for _ in range(6)]
    for v, f in cushion.cushion_meshes(pairs, subdivisions):
        check_convex_closed(v, f)
        reference = ConvexHull(v)
        assert mesh.volume(v, f) == pytest.approx(reference.volume, rel=1e-9)
        # Signed distance of every vertex to each of scipy's facet planes (unit normals, <= 0 inside): the
        # largest is the vertex's distance to the hull's surface, so 0 means on it, never inside it.
        heights = reference.equations[:, :3] @ v.T + reference.equations[:, 3:]
        assert np.all(heights.max(axis=0) >= -1e-12) and heights.max() <= 1e-12


def test_identical_and_nested_ellipsoids():
    e = (rotation_from_vector((0.3, 0.2, 0.1)), (0.1, 0.2, 0.3), (0.05, 0.1, 0.15))
    v, f = cushion.cushion_mesh(e, e)
    check_convex_closed(v, f)
    small = (np.eye(3), (0.1, 0.2, 0.3), (0.02, 0.02, 0.02))
    v, f = cushion.cushion_mesh(e, small)
    check_convex_closed(v, f)
    assert np.all(contains(e[0], e[1], e[2], v, tol=1e-9))


def test_a_batch_builds_every_pair_as_if_alone(monkeypatch):
    """cushion_meshes runs all pairs through shared arrays; each mesh must be exactly the one built alone,
    also next to a flat pair whose folded triangulation is rebuilt by the exact hull."""
    flat = (
        (rotation_from_vector((0.3, 0.5, 0.1)), (0, 0, 0), (0.2, 0.02, 0.15)),
        (np.eye(3), (0.05, 0.02, 0.25), (0.08, 0.1, 0.12)),
    )
    capsule = ((np.eye(3), (0, 0, 0), (0.1, 0.1, 0.1)), (np.eye(3), (0, 0, 0.3), (0.1, 0.1, 0.1)))
    rng = np.random.default_rng(3)
    pairs = [random_pair(rng), flat, capsule, (capsule[0], capsule[0]), random_pair(rng)]
    exact_hulls = []
    real_hull = cushion.convex_hull_3d
    monkeypatch.setattr(cushion, "convex_hull_3d", lambda points: exact_hulls.append(len(points)) or real_hull(points))
    batch = cushion.cushion_meshes(pairs, 3)
    assert len(exact_hulls) == 1  # the flat pair, and only it
    for pair, (v, f) in zip(pairs, batch):
        check_convex_closed(v, f)
        alone_v, alone_f = cushion.cushion_mesh(*pair, 3)
        assert np.array_equal(v, alone_v) and np.array_equal(f, alone_f)
    assert len(exact_hulls) == 2 and cushion.cushion_meshes([], 3) == []


def test_a_fold_left_by_the_flips_is_mended_into_the_exact_hull_from_a_small_patch(monkeypatch):
    """The shipped Average's right foot and toes: the flips end locally convex but folded (a few faces face the
    interior); the faces around the fold are rebuilt from the hull of a few of the points, not all of them."""
    average = Mannequin.load(REFERENCE_FOLDER / "average.json")
    pair = [
        tuple(a[average.topology.index[name]] for a in (average.rotation, average.center, average.semi_axes))
        for name in ("7.a Foot.R", "7.b Toes.R")
    ]
    hulled = []
    real_hull = cushion.convex_hull_3d
    monkeypatch.setattr(cushion, "convex_hull_3d", lambda points: hulled.append(len(points)) or real_hull(points))
    v, f = cushion.cushion_mesh(*pair)
    assert len(hulled) == 1 and 4 <= hulled[0] < len(v) // 10, hulled  # the fold's patch only
    check_convex_closed(v, f)
    assert {tuple(sorted(face)) for face in f.tolist()} == {tuple(sorted(face)) for face in real_hull(v).tolist()}
    # what cannot be mended is left to the whole hull: here every face is wrong
    assert cushion._mend_fold(v, f[:, ::-1], 0.5 * (pair[0][1] + pair[1][1])) is None


def test_mannequin_cushions_are_the_hulls_of_its_pairs(toy):
    world, local = cushion.mannequin_cushions(toy, 2), cushion.mannequin_cushions(toy, 2, local=True)
    assert [(h.first, h.second) for h in world] == toy.topology.cushion_pairs == [(1, 2), (8, 9), (10, 11)]
    assert [h.name for h in world] == ["2.a Chest + 2.b Belly", "6.a Thigh.L + 6.b Shin.L", "6.a Thigh.R + 6.b Shin.R"]
    for hull, in_frame in zip(world, local):
        pair = [(toy.rotation[i], toy.center[i], toy.semi_axes[i]) for i in (hull.first, hull.second)]
        alone = cushion.cushion_mesh(*pair, 2)
        assert np.array_equal(hull.vertices, alone[0]) and np.array_equal(hull.faces, alone[1])
        r, c = toy.rotation[hull.first], toy.center[hull.first]
        assert np.allclose(in_frame.vertices @ r.T + c, hull.vertices, rtol=0, atol=1e-15)
        assert np.array_equal(in_frame.faces, hull.faces) and in_frame.name == hull.name


def test_to_frame_expresses_vertices_in_the_first_frame():
    r = rotation_from_vector((0.4, -0.2, 1.0))
    e1 = (r, (1.0, 2.0, 3.0), (0.1, 0.2, 0.3))
    e2 = (np.eye(3), (1.2, 2.0, 3.0), (0.1, 0.1, 0.1))
    v, _ = cushion.cushion_mesh(e1, e2, 2)
    local = cushion.to_frame(v, r, e1[1])
    assert np.allclose(local @ r.T + e1[1], v)


def test_exact_hull_of_points_in_convex_position():
    pts = mesh.icosphere(2)[0] * (0.1, 0.3, 0.2)
    f = cushion.convex_hull_3d(pts)
    check_convex_closed(pts, f)
    assert len(f) == 2 * len(pts) - 4


def test_icosphere_sizes_and_orientation():
    for s in range(4):
        v, f = mesh.icosphere(s)
        assert len(v) == 10 * 4**s + 2 and len(f) == 20 * 4**s
        check_convex_closed(v, f)


def test_icosphere_level_is_read_back_from_the_vertex_count():
    for s in range(8):
        assert mesh.icosphere_vertex_count(s) == 10 * 4**s + 2
        assert mesh.icosphere_level(mesh.icosphere_vertex_count(s)) == s
    assert mesh.icosphere_level(len(mesh.icosphere(3)[0])) == 3
    for count in (0, 1, 11, 13, 41, 43, 641, 2561, 10 * 4**8 + 1):
        assert mesh.icosphere_level(count) is None


def test_subdivision_levels_are_integers_in_the_allowed_range():
    assert mesh.check_subdivision_level("level", 3, (1, 6)) == 3
    assert type(mesh.check_subdivision_level("level", np.int64(1), (1, 6))) is int
    for bad in (0, 7, 3.0, True, "3", None):
        with pytest.raises(ElliMannError, match=r"level: must be an integer from 1 to 6, got "):
            mesh.check_subdivision_level("level", bad, (1, 6))


@pytest.mark.parametrize("subdivisions", [2, 4])
def test_cushion_vertices_are_the_hull_builders_support_points_for_every_pair_at_once(subdivisions):
    reference = synthetic.make_reference_set()
    mannequin, _, _ = synthesize(reference, REFERENCE_MEASUREMENTS["small_chubby"], mode="exact")
    pairs = mannequin.topology.cushion_pairs
    batch = cushion.cushion_vertices(mannequin.rotation, mannequin.center, mannequin.semi_axes, pairs, subdivisions)
    assert batch.shape == (len(pairs), 10 * 4**subdivisions + 2, 3)
    for vertices, (i, j) in zip(batch, pairs):
        first = (mannequin.rotation[i], mannequin.center[i], mannequin.semi_axes[i])
        second = (mannequin.rotation[j], mannequin.center[j], mannequin.semi_axes[j])
        world, _ = cushion.cushion_mesh(first, second, subdivisions)
        np.testing.assert_allclose(vertices, cushion.to_frame(world, first[0], first[1]), atol=1e-12)
