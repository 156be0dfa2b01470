import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from devkit.toy import rotation_from_vector
from ellimann_addon.core.errors import FrameError
from ellimann_addon.core.geometry import ellipsoid as el
from ellimann_addon.core.geometry.frames import is_rotation

vectors = st.tuples(*[st.floats(-3, 3)] * 3)
sizes = st.tuples(*[st.floats(0.02, 0.3)] * 3)
points3 = st.tuples(*[st.floats(-1, 1)] * 3)


@settings(max_examples=60, deadline=None)
@given(vectors, points3, sizes, vectors)
def test_support_is_the_max_over_surface_points(rv, c, d, n):
    n = np.asarray(n)
    if np.linalg.norm(n) < 1e-3:
        return
    n = n / np.linalg.norm(n)
    e = el.Ellipsoid(c, rotation_from_vector(rv), d)
    samples = e.sample(4000)
    assert e.support(n) >= (samples @ n).max() - 1e-12
    assert e.support(n) == pytest.approx((samples @ n).max(), abs=2e-3 * max(d))
    p = e.support_point(n)
    assert p @ n == pytest.approx(e.support(n), abs=1e-12)
    assert e.contains(p[None], tol=1e-9)[0]


def test_support_and_point_in_shared_directions_of_axis_aligned_ellipsoids():
    """Closed form for R = I: h(n) = c.n + |D n| and p = c + D^2 n / |D n|, each ellipsoid in every direction."""
    center = np.array([(0.1, -0.2, 0.3), (-1.0, 0.5, 2.0)])
    semi = np.array([(0.1, 0.2, 0.3), (0.5, 0.05, 0.25)])
    directions = np.random.default_rng(4).normal(size=(7, 3))  # not unit: h is positively homogeneous
    h, points = el.support_and_point(np.stack([np.eye(3)] * 2), center, semi, directions)
    assert h.shape == (2, 7) and points.shape == (2, 7, 3)
    for i in range(2):
        scaled = np.linalg.norm(directions * semi[i], axis=1)
        assert np.allclose(h[i], directions @ center[i] + scaled, rtol=1e-14)
        assert np.allclose(points[i], center[i] + directions * semi[i] ** 2 / scaled[:, None], rtol=1e-14)
        assert np.allclose(el.support(np.eye(3), center[i], semi[i], directions), h[i], rtol=1e-14)


@settings(max_examples=60, deadline=None)
@given(vectors, points3, sizes, st.floats(-0.99, 0.99))
def test_section_ellipse_lies_on_the_surface(rv, c, d, frac):
    e = el.Ellipsoid(c, rotation_from_vector(rv), d)
    z_half = el.axis_extent(e.rotation, e.semi_axes, 2)
    height = e.center[2] + frac * z_half
    centre, k, hit = e.section(height)
    assert hit
    w, v = np.linalg.eigh(k)
    t = np.linspace(0, 2 * np.pi, 64)
    boundary = centre + (np.stack([np.cos(t), np.sin(t)], -1) * np.sqrt(w)) @ v.T
    points = np.column_stack([boundary, np.full(len(t), height)])
    local = (points - e.center) @ e.rotation / e.semi_axes
    assert np.allclose(np.sum(local**2, axis=1), 1.0, atol=1e-9)


def test_section_misses_above_and_below():
    e = el.Ellipsoid.sphere((0, 0, 1), 0.2)
    assert not e.section(1.21)[2] and not e.section(0.79)[2] and e.section(1.19)[2]


def test_section_extent_is_the_section_s_middle_and_half_width_bit_for_bit():
    rng = np.random.default_rng(6)
    rotation = np.stack([rotation_from_vector(v) for v in rng.normal(size=(50, 3))]).reshape(10, 5, 3, 3)
    center, semi = rng.normal(0.0, 0.3, size=(10, 5, 3)), rng.uniform(0.02, 0.3, size=(10, 5, 3))
    heights = rng.normal(0.0, 0.4, size=(10, 4, 1))  # several heights per stack, some missing the ellipsoids
    centre, k, hit = el.section_at_height(rotation[:, None], center[:, None], semi[:, None], heights)
    assert hit.any() and not hit.all()
    for axis in (0, 1):
        middle, half, hits = el.section_extent(rotation[:, None], center[:, None], semi[:, None], heights, axis)
        assert middle.tobytes() == centre[..., axis].tobytes()
        assert half.tobytes() == np.sqrt(k[..., axis, axis]).tobytes()
        assert np.array_equal(hits, hit)


def test_sphere_section_through_centre_is_a_circle_of_radius_r():
    centre, k, hit = el.Ellipsoid.sphere((0.3, -0.2, 1.0), 0.25).section(1.0)
    assert hit and np.allclose(centre, (0.3, -0.2)) and np.allclose(k, np.eye(2) * 0.25**2)


def test_points_in_a_frame_are_their_offsets_along_its_axes():
    rotation = rotation_from_vector((0, 0, np.pi / 2))  # local x along world y, local y along world -x
    origin = np.array([1.0, 2.0, 3.0])
    points = origin + np.array([[0.0, 0.5, 0.0], [-0.25, 0.0, 0.0], [0.0, 0.0, 2.0]])
    assert np.allclose(el.to_frame(points, origin, rotation), [[0.5, 0, 0], [0, 0.25, 0], [0, 0, 2]], atol=1e-15)
    mesh = np.random.default_rng(1).normal(size=(5000, 3))  # long enough that a BLAS product would thread
    assert np.allclose(el.to_frame(mesh, origin, rotation), (mesh - origin) @ rotation, rtol=0, atol=1e-14)


def test_bounds_and_volume_closed_forms():
    e = el.Ellipsoid((1, 2, 3), rotation_from_vector((0, 0, np.pi / 2)), (0.1, 0.2, 0.3))
    lo, hi = el.bounds(e.rotation, e.center, e.semi_axes)
    assert np.allclose(lo, (0.8, 1.9, 2.7)) and np.allclose(hi, (1.2, 2.1, 3.3))
    assert e.volume == pytest.approx(4 / 3 * np.pi * 0.006)


@settings(max_examples=40, deadline=None)
@given(vectors, points3, sizes)
def test_matrix_world_round_trip(rv, c, d):
    r = rotation_from_vector(rv)
    back = el.decompose_matrix_world(el.matrix_world(r, c, d))
    assert np.allclose(back[0], r, atol=1e-9) and np.allclose(back[1], c) and np.allclose(back[2], d)


def test_decompose_refuses_negative_scale_shear_and_zero_scale():
    m = el.matrix_world(np.eye(3), (0, 0, 0), (0.1, 0.2, 0.3))
    negative = m.copy()
    negative[:3, 0] *= -1
    with pytest.raises(FrameError, match="left-handed") as info:
        el.decompose_matrix_world(negative)
    assert info.value.kind == "negative"
    sheared = m.copy()
    sheared[0, 1] = 0.1
    with pytest.raises(FrameError, match="sheared") as info:
        el.decompose_matrix_world(sheared)
    assert info.value.kind == "shear"
    flat = m.copy()
    flat[:3, 2] = 0
    with pytest.raises(FrameError, match="zero axis") as info:
        el.decompose_matrix_world(flat)
    assert info.value.kind == "zero"
    with pytest.raises(FrameError, match="finite"):
        el.decompose_matrix_world(np.full((4, 4), np.nan))


def test_decomposing_a_stack_is_one_decomposition_per_matrix_or_none_if_any_is_not_a_frame():
    rng = np.random.default_rng(7)
    good = np.array(
        [
            el.matrix_world(rotation_from_vector(rng.normal(size=3)), rng.normal(size=3), rng.uniform(0.02, 0.3, 3))
            for _ in range(12)
        ]
    )
    stacked = el.decompose_matrices_world(good)
    for i, matrix in enumerate(good):
        for got, one in zip(stacked, el.decompose_matrix_world(matrix)):
            assert np.array_equal(got[i], one)
    bad = {"negative": (slice(None), 0, -1.0), "sheared": (0, 1, 0.1), "zero": (slice(None), 2, 0.0)}
    for kind, (row, column, value) in bad.items():
        broken = good.copy()
        if kind == "sheared":
            broken[5, row, column] += value
        else:
            broken[5, :3, column] *= value
        with pytest.raises(FrameError):
            el.decompose_matrix_world(broken[5])
        assert el.decompose_matrices_world(broken) is None, kind
    for value in (np.nan, np.inf):
        broken = good.copy()
        broken[3, 0, 0] = value
        assert el.decompose_matrices_world(broken) is None
    projective = good.copy()
    projective[0, 3, 0] = 0.5
    assert el.decompose_matrices_world(projective) is None


def is_frame(matrix):
    try:
        el.decompose_matrix_world(matrix)
    except FrameError:
        return False
    return True


def same_set(matrix, repaired):
    """Two descriptions of one ellipsoid: same centre and same shape matrix L L^T."""
    rotation, center, semi = repaired
    linear = np.asarray(matrix)[:3, :3]
    return np.allclose(center, np.asarray(matrix)[:3, 3]) and np.allclose(
        el.shape_matrix(rotation, semi), linear @ linear.T, atol=1e-12
    )


@settings(max_examples=30, deadline=None)
@given(vectors, points3, sizes, st.integers(0, 2))
def test_repair_of_negative_scale_keeps_the_set_and_the_other_axes(rv, c, d, axis):
    r = rotation_from_vector(rv)
    m = el.matrix_world(r, c, d)
    m[:3, axis] *= -1
    repaired = el.repair_matrix_world(m, flip_axis=axis)
    assert same_set(m, repaired) and is_rotation(repaired[0])
    assert np.allclose(repaired[0], r, atol=1e-9) and np.allclose(repaired[2], d)
    auto = el.repair_matrix_world(m)
    assert same_set(m, auto) and is_rotation(auto[0])
    el.decompose_matrix_world(el.matrix_world(*auto))


@settings(max_examples=30, deadline=None)
@given(st.lists(st.floats(-1, 1), min_size=9, max_size=9), points3)
def test_repair_of_shear_gives_a_valid_frame_for_the_same_set(entries, c):
    linear = np.eye(3) * 0.3 + np.reshape(entries, (3, 3)) * 0.05  # singular values >= 0.15
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = linear, c
    assume(not is_frame(m))  # one within the frames' tolerance is a frame: projected, not repaired
    repaired = el.repair_matrix_world(m)
    assert same_set(m, repaired) and is_rotation(repaired[0]) and np.all(repaired[2] > 0)
    el.decompose_matrix_world(el.matrix_world(*repaired))


def test_repair_leaves_a_valid_frame_alone_and_refuses_a_flat_one():
    r = rotation_from_vector((0.2, 0.4, -0.1))
    m = el.matrix_world(r, (1, 2, 3), (0.1, 0.2, 0.3))
    rotation, center, semi = el.repair_matrix_world(m)
    assert np.allclose(rotation, r) and np.allclose(center, (1, 2, 3)) and np.allclose(semi, (0.1, 0.2, 0.3))
    flat = m.copy()
    flat[:3, 1] = flat[:3, 0]
    with pytest.raises(FrameError, match="zero along some axis"):
        el.repair_matrix_world(flat)


def test_linear_image_of_an_ellipsoid_is_its_mapped_set_with_its_axes_named_as_before():
    """A stretch along a unit axis a (A = I + (f - 1) a a^T) of a sphere is a spheroid of semi-axes (r, r, f r)
    with its long axis along a; touching ellipsoids stay touching (the contact point maps onto both images); the
    identity keeps every axis, and a small map keeps each axis its name (the one nearest before)."""
    axis = np.array([0.3, -0.4, 0.866])
    axis /= np.linalg.norm(axis)
    stretch = np.eye(3) + 0.5 * np.outer(axis, axis)  # f = 1.5
    rotation, semi = el.linear_image(np.eye(3), np.full(3, 0.2), stretch)
    assert is_rotation(rotation) and sorted(semi) == pytest.approx([0.2, 0.2, 0.3], abs=1e-12)
    assert abs(rotation[:, np.argmax(semi)] @ axis) == pytest.approx(1.0, abs=1e-12)
    # two ellipsoids touching at a point: the images touch at its image
    r0, r1 = rotation_from_vector((0.3, 0.2, -0.1)), rotation_from_vector((-0.5, 0.1, 0.7))
    semi0, semi1 = np.array([0.1, 0.05, 0.2]), np.array([0.08, 0.12, 0.04])
    normal = np.array([0.2, 0.9, -0.3]) / np.linalg.norm([0.2, 0.9, -0.3])
    contact = el.support_point(r0, np.zeros(3), semi0, normal)
    center1 = contact - (el.support_point(r1, np.zeros(3), semi1, -normal))  # its support point at -n is there
    for rotation_k, center_k, semi_k in ((r0, np.zeros(3), semi0), (r1, center1, semi1)):
        new_rotation, new_semi = el.linear_image(rotation_k, semi_k, stretch)
        surface = np.vstack([contact, el.sample_surface(rotation_k, center_k, semi_k, 200)])
        local = (surface - center_k) @ stretch.T @ new_rotation / new_semi  # mapped, in the image's frame
        assert np.allclose(np.linalg.norm(local, axis=1), 1.0, atol=1e-9)  # on the image's surface
    same = el.linear_image(r0, semi0, np.eye(3))
    assert np.allclose(same[0], r0, atol=1e-12) and np.allclose(same[1], semi0, atol=1e-12)
    nudged = el.linear_image(r0, semi0, np.eye(3) + 0.05 * np.outer(axis, axis))
    assert np.all(np.einsum("ij,ij->j", nudged[0], r0) > 0.99)  # each axis near its old self
