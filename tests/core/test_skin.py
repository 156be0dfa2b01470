"""The skin (core.skin): its meshing is closed and 2-manifold whatever the field, one ellipsoid's skin is that
ellipsoid, two neighbours blend with the documented bulge and two non-neighbours do not, the narrow band gives
the whole grid's mesh, a body's skin is one closed oriented sphere without self-intersections holding every
piece, and exact mode on the skin meets the request on its mesh."""

import math

import numpy as np
import pytest

from devkit.mesh_checks import self_intersections, vertex_manifold
from ellimann_addon.core.constants import MEASUREMENTS, TABLE_2_5
from ellimann_addon.core.drape.fit_metrics import mesh_distance
from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.geometry.ellipsoid import sample_surface
from ellimann_addon.core.geometry.mesh import euler_characteristic, is_closed_manifold, section_segments, volume
from ellimann_addon.core.measure.body import measure_body_mesh
from ellimann_addon.core.skin.contour import marching_cubes
from ellimann_addon.core.skin.exact import MESH_TOLERANCE_CM, exact_skin
from ellimann_addon.core.skin.field import PieceField, blend_pairs, blend_widths, sample_field
from ellimann_addon.core.skin.measure import field_measurements, mesh_measurements
from ellimann_addon.core.skin.settings import SkinSettings
from ellimann_addon.core.skin.surface import SkinError, build_skin, outer_surface
from ellimann_addon.core.synthesis.shipped import named_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize

MESHING_ERROR_M = 0.0065  # how far a piece may poke out of its 10 mm skin (the fingers' mitten: 4.7-5.9 mm measured)


@pytest.fixture(scope="module")
def female():
    return named_reference_set("female")


def box_field(shape, seed):
    """A random field with an outside boundary (every crossing inside the grid)."""
    values = np.random.default_rng(seed).normal(size=shape)
    values[[0, -1]], values[:, [0, -1]], values[:, :, [0, -1]] = 1.0, 1.0, 1.0
    return values


@pytest.mark.parametrize("seed", range(40))
def test_marching_cubes_is_closed_manifold_and_outward_on_any_field(seed):
    vertices, faces, _ = marching_cubes(box_field((8, 7, 9), seed), (0.0, 0.0, 0.0), 1.0)
    assert is_closed_manifold(faces) and vertex_manifold(faces, len(vertices))
    assert volume(vertices, faces) > 0.0  # wound counter-clockwise from outside: outward normals


def test_marching_cubes_of_a_sphere_matches_its_volume_and_has_one_sphere_s_topology():
    h = 0.05
    axis = np.arange(-1.3, 1.3 + 1e-9, h)
    x, y, z = np.meshgrid(axis, axis, axis, indexing="ij")
    vertices, faces, _ = marching_cubes(np.sqrt(x * x + y * y + z * z) - 1.0, (axis[0],) * 3, h)
    assert euler_characteristic(vertices, faces) == 2
    assert abs(volume(vertices, faces) / (4.0 / 3.0 * math.pi) - 1.0) < 0.01
    assert np.allclose(np.linalg.norm(vertices, axis=1), 1.0, atol=h * h)  # vertices on the surface, to O(h^2)


def one_piece(semi_axes, rotation=None):
    rotation = np.eye(3) if rotation is None else np.asarray(rotation)
    return rotation[None], np.zeros((1, 3)), np.asarray(semi_axes, float)[None]


def skin_of(arrays, pairs, widths, spacing):
    values, grid, _ = sample_field(*arrays, np.asarray(pairs, dtype=np.int64).reshape(-1, 2), widths, spacing)
    return marching_cubes(values, grid.origin, grid.spacing)[:2]


def ramanujan(a, b):
    h = ((a - b) / (a + b)) ** 2
    return math.pi * (a + b) * (1 + 3 * h / (10 + math.sqrt(4 - 3 * h)))


def test_one_ellipsoid_s_skin_is_that_ellipsoid():
    rotation = np.linalg.qr(np.random.default_rng(3).normal(size=(3, 3)))[0]
    rotation *= np.sign(np.linalg.det(rotation))
    semi = np.array([0.12, 0.08, 0.05])
    spacing = 0.004
    vertices, faces = skin_of(one_piece(semi, rotation), [], np.zeros(0), spacing)
    assert is_closed_manifold(faces) and euler_characteristic(vertices, faces) == 2
    assert abs(volume(vertices, faces) / (4.0 / 3.0 * math.pi * semi.prod()) - 1.0) < 0.01
    # every vertex on the ellipsoid, to the linear interpolation's error
    local = vertices @ rotation
    assert np.allclose(np.linalg.norm(local / semi, axis=1), 1.0, atol=0.01)


def test_an_upright_ellipsoid_s_skin_has_its_section_perimeter():
    semi = np.array([0.15, 0.10, 0.30])
    vertices, faces = skin_of(one_piece(semi), [], np.zeros(0), 0.004)
    segments, _ = section_segments(vertices, faces, 0.0)
    perimeter = np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1).sum()
    assert abs(perimeter / ramanujan(0.15, 0.10) - 1.0) < 0.002


def two_spheres(gap, radius=0.1):
    rotation = np.repeat(np.eye(3)[None], 2, axis=0)
    center = np.array([[-(radius + gap / 2), 0.0, 0.0], [radius + gap / 2, 0.0, 0.0]])
    return rotation, center, np.full((2, 3), radius)


def neck_radius(vertices, faces):
    """The skin's radius in the plane x = 0 between two spheres on the x axis (0 where it does not cross it)."""
    turned = vertices[:, [1, 2, 0]]  # x becomes the height
    segments, _ = section_segments(turned, faces, 0.0)
    return float(np.linalg.norm(segments.reshape(-1, 2), axis=1).mean()) if len(segments) else 0.0


def test_two_touching_neighbours_blend_with_the_documented_bulge():
    radius, width, spacing = 0.1, 0.04, 0.002
    vertices, faces = skin_of(two_spheres(0.0, radius), [(0, 1)], np.array([width]), spacing)
    # between two equal spheres the field is d - width / 4: the neck is where the distance is width / 4
    expected = math.sqrt((radius + width / 4) ** 2 - radius**2)
    assert abs(neck_radius(vertices, faces) - expected) < 0.1 * spacing + 1e-4
    plain = skin_of(two_spheres(0.0, radius), [], np.zeros(0), spacing)
    assert neck_radius(*plain) < 2 * spacing  # without the pair, a pinch


def test_non_neighbours_do_not_web_and_neighbours_bridge_a_small_gap():
    spacing, gap = 0.002, 0.004
    vertices, faces = skin_of(two_spheres(gap), [], np.zeros(0), spacing)
    with pytest.raises(SkinError, match="falls apart"):  # two bodies, left apart: no webbing
        outer_surface(vertices, faces, np.zeros(len(vertices), int), np.zeros(1, int), ["a", "b"])
    vertices, faces = skin_of(two_spheres(gap), [(0, 1)], np.array([0.04]), spacing)
    assert euler_characteristic(vertices, faces) == 2  # one body


def test_the_neighbours_of_a_body_are_its_joints_and_cushions_never_left_with_right(female):
    topology = female.mannequins[0].topology
    names = topology.names
    pairs = {(names[i], names[j]) for i, j in blend_pairs(topology)}
    pairs |= {(b, a) for a, b in pairs}
    assert ("3.a Upper Arm.L", "3.b Forearm.L") in pairs  # cushion partners across the elbow
    assert ("5.a Thigh.L", "14.a Pelvis") in pairs  # a bone and its child
    assert ("8.a Deltoid.L", "11.a Thorax") in pairs  # the shoulder's pieces with the chest's
    assert ("5.a Thigh.L", "5.a Thigh.R") not in pairs  # left and right meet in a crease
    assert ("3.a Upper Arm.L", "11.a Thorax") not in pairs  # the arm beside the torso
    assert ("4.a Hand.L", "12.b Hip.L") not in pairs  # the hand near the hip


def test_the_narrow_band_gives_the_whole_grid_s_mesh(female):
    m, _, _ = synthesize(female, TABLE_2_5[3])
    pairs = blend_pairs(m.topology)
    widths = blend_widths(m.semi_axes, pairs, SkinSettings().blend)
    # 16 mm voxels: the narrowing is the same at any voxel, and the whole grid's field costs 4x less than at 10 mm
    values, grid, _ = sample_field(m.rotation, m.center, m.semi_axes, pairs, widths, 0.016)
    whole, _ = PieceField(m.rotation, m.center, m.semi_axes, pairs, widths).field(
        grid, np.ones(grid.shape, dtype=bool), 1.0
    )
    narrow = marching_cubes(values, grid.origin, grid.spacing)
    dense = marching_cubes(whole, grid.origin, grid.spacing)
    assert np.array_equal(narrow[0], dense[0]) and np.array_equal(narrow[1], dense[1])


@pytest.mark.parametrize("index", range(5))  # not slow (about 5 s each): on numpy 1 and 2 alike
def test_a_reference_mannequin_s_skin_is_one_closed_oriented_sphere_holding_every_piece(female, index):
    m = female.mannequins[index]
    skin = build_skin(m, SkinSettings(10.0))
    vertices, faces = skin.vertices, skin.faces
    assert is_closed_manifold(faces) and vertex_manifold(faces, len(vertices))
    assert euler_characteristic(vertices, faces) == 2 and skin.volume > 0.0
    assert len(self_intersections(vertices, faces)) == 0
    # every piece inside: points on each piece's surface inside the skin or outside by at most the meshing's error
    # (exact signed distance; at 10 mm the fingers' mitten, 1 cm thin, pokes out by up to 6 mm)
    points = np.concatenate([sample_surface(r, c, s, 100) for r, c, s in zip(m.rotation, m.center, m.semi_axes)])
    assert mesh_distance(points, vertices, faces)[0].max() <= MESHING_ERROR_M
    assert np.allclose(skin.weights.sum(axis=1), 1.0) and skin.pieces.shape == (len(vertices), 4)


def test_following_the_same_pieces_leaves_the_skin_where_it_is_and_a_move_moves_it_rigidly(female):
    skin = build_skin(female.mannequins[4], SkinSettings(10.0))
    assert np.allclose(skin.following(skin.mannequin).vertices, skin.vertices, atol=1e-12)
    moved = skin.mannequin.translated(np.array([0.1, -0.2, 0.3]))
    assert np.allclose(skin.following(moved).vertices, skin.vertices + [0.1, -0.2, 0.3], atol=1e-12)
    bones, weights = skin.bones()
    assert np.allclose(weights.sum(axis=1), 1.0) and bones.shape == (len(skin.vertices), 4)


def test_the_surface_and_the_mesh_measure_alike_and_the_mesh_measurer_agrees(female):
    settings = SkinSettings(5.0)
    m = female.mannequins[1]
    skin = build_skin(m, settings)
    on_mesh, on_surface = mesh_measurements(skin), field_measurements(m, settings)
    for key in MEASUREMENTS:
        assert abs(on_mesh[key] - on_surface[key]) < 0.05, key  # half a millimetre
    body = measure_body_mesh(skin.vertices, skin.faces, m.section_fractions).values
    for key in MEASUREMENTS:
        assert abs(body[key] - on_mesh[key]) < 1e-6, key  # the arms hang apart: the same definitions


@pytest.mark.slow
@pytest.mark.parametrize("request_", TABLE_2_5[::3])
def test_exact_mode_on_the_skin_meets_the_request_on_its_mesh(female, request_):
    m, _, _ = synthesize(female, request_)
    result = exact_skin(m, SkinSettings(5.0))
    measured = mesh_measurements(result.skin)
    for key, wanted in zip(MEASUREMENTS, request_):
        assert abs(measured[key] - wanted) <= MESH_TOLERANCE_CM, key  # 1 mm
    assert result.converged and result.misses() == []
    assert any(abs(result.pieces_measured[k] - w) > MESH_TOLERANCE_CM for k, w in zip(MEASUREMENTS, request_))


def test_a_voxel_too_fine_for_memory_or_too_coarse_for_a_piece_is_refused_before_any_work(female):
    m = female.mannequins[4]
    with pytest.raises(SkinError, match=r"skin_voxel: 1 mm voxels would need about .* GB .* mm or coarser fits"):
        build_skin(m, SkinSettings(1.0))
    with pytest.raises(SkinError, match=r"Fingers.* too thin for 20 mm voxels.* mm or finer keeps every piece"):
        build_skin(m, SkinSettings(20.0))
    for bad in (float("nan"), -5.0, 0.2, 100.0, True):
        with pytest.raises(ElliMannError, match="skin_voxel: must be a number from 1 to 40"):
            SkinSettings(bad)


def test_a_topology_off_the_skeleton_blends_by_partners_and_regions(toy):
    """A reference set of one's own may label its parts as it likes: no bone, yet a skin (no bone clause)."""
    names = toy.topology.names
    pairs = {(names[i], names[j]) for i, j in blend_pairs(toy.topology)}
    assert pairs and all(not (a.endswith(".L") and b.endswith(".R")) for a, b in pairs)
    assert any({"2.a Chest", "2.b Belly"} == {a, b} for a, b in pairs)
