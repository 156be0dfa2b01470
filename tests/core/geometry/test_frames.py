import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from devkit.toy import rotation_from_vector
from ellimann_addon.core.geometry import frames
from ellimann_addon.core.geometry.ellipsoid import shape_matrix

vectors = st.tuples(*[st.floats(-3.2, 3.2)] * 3)
sizes = st.tuples(*[st.floats(0.01, 0.5)] * 3)
points3 = st.tuples(*[st.floats(-1, 1)] * 3)
F = np.diag([-1.0, 1.0, 1.0])


def test_there_are_24_proper_signed_permutations():
    q = frames.SIGNED_PERMUTATIONS
    assert q.shape == (24, 3, 3)
    assert np.all(frames.is_rotation(q))
    assert len({tuple(m.ravel()) for m in q}) == 24


@settings(max_examples=100, deadline=None)
@given(vectors, points3, st.sampled_from([None, 0, 1, 2]))
def test_mirror_stays_right_handed_and_twice_is_identity(rv, c, axis):
    r = rotation_from_vector(rv)
    m, mc = frames.mirror_frame(r, c, axis)
    assert frames.is_rotation(m)
    assert np.allclose(mc, np.asarray(c) * (-1, 1, 1))
    r2, c2 = frames.mirror_frame(m, mc, axis)
    assert np.array_equal(r2, r) and np.allclose(c2, c)


@settings(max_examples=60, deadline=None)
@given(vectors, sizes)
def test_mirrored_ellipsoid_is_the_reflected_set(rv, d):
    r = rotation_from_vector(rv)
    m, _ = frames.mirror_frame(r, np.zeros(3))
    assert np.allclose(shape_matrix(m, d), F @ shape_matrix(r, d) @ F, atol=1e-12)


def test_mirror_keeps_the_long_axis_of_a_vertical_limb():
    r = rotation_from_vector((0.0, 0.2, 0.0))  # slightly tilted about Y: local x is mostly world X
    m, _ = frames.mirror_frame(r, np.zeros(3))
    assert m[:, 2] @ r[:, 2] > 0.9  # local z still points the same way up/down


@settings(max_examples=100, deadline=None)
@given(vectors, vectors, sizes)
def test_relabel_keeps_the_set_and_maximises_agreement(rv, rv_ref, d):
    r, ref = rotation_from_vector(rv), rotation_from_vector(rv_ref)
    new, new_d, q = frames.relabel_to_reference(r, np.asarray(d), ref)
    assert frames.is_rotation(new)
    assert np.allclose(shape_matrix(new, new_d), shape_matrix(r, d), atol=1e-12)
    best = max(np.trace(ref.T @ r @ qq) for qq in frames.SIGNED_PERMUTATIONS)
    assert np.trace(ref.T @ new) == pytest.approx(best)


@settings(max_examples=60, deadline=None)
@given(vectors, st.integers(0, 23), sizes)
def test_relabel_undoes_any_relabelling(rv, k, d):
    ref = rotation_from_vector(rv)
    q = frames.SIGNED_PERMUTATIONS[k]
    scrambled_d = np.abs(q).T @ np.asarray(d)
    new, new_d, _ = frames.relabel_to_reference(ref @ q, scrambled_d, ref)
    assert np.allclose(new, ref) and np.allclose(new_d, d)


@settings(max_examples=100, deadline=None)
@given(vectors, points3, sizes)
def test_symmetrize_central_gives_a_symmetric_right_handed_ellipsoid(rv, c, d):
    r = rotation_from_vector(rv)
    s, sc = frames.symmetrize_central(r, c)
    assert frames.is_rotation(s) and sc[0] == 0.0
    m = shape_matrix(s, d)
    assert np.allclose(F @ m @ F, m, atol=1e-12)
    k = np.argmax(np.abs(s[0]))
    assert abs(s[0, k]) == 1.0


def nearest_rotation_by_svd(matrix):
    u, _, vt = np.linalg.svd(matrix)
    fix = np.ones(matrix.shape[:-1])
    fix[..., 2] = np.linalg.det(u @ vt)
    return (u * fix[..., None, :]) @ vt


@settings(max_examples=60, deadline=None)
@given(vectors, sizes)
def test_the_nearest_rotation_to_a_rotation_times_a_stretch_is_that_rotation(rv, stretch):
    r = rotation_from_vector(rv)
    assert np.allclose(frames.project_to_rotation(r @ np.diag(stretch)), r, atol=1e-12)  # polar factor R
    assert np.allclose(frames.project_to_rotation(0.3 * r), r, atol=1e-13)


def test_the_nearest_rotation_is_the_svd_s_for_any_matrix_and_the_same_alone_as_in_a_batch():
    rng = np.random.default_rng(3)
    near = np.stack([rotation_from_vector(v) for v in rng.normal(size=(200, 3))]) + 0.2 * rng.normal(size=(200, 3, 3))
    matrices = np.concatenate([near, rng.normal(size=(200, 3, 3))])  # about half of the random ones: det < 0
    assert (np.linalg.det(matrices) < 0).sum() > 50
    nearest = frames.project_to_rotation(matrices)
    assert np.allclose(nearest, nearest_rotation_by_svd(matrices), rtol=0, atol=1e-12)
    assert np.all(frames.is_rotation(nearest, tol=1e-13))
    alone = np.stack([frames.project_to_rotation(m) for m in matrices])
    assert np.array_equal(alone, nearest)
    assert frames.project_to_rotation(matrices.reshape(20, 20, 3, 3)).shape == (20, 20, 3, 3)


def test_a_matrix_whose_iteration_would_overflow_is_projected_by_the_svd():
    r = rotation_from_vector((0.3, -0.2, 0.1))
    assert np.allclose(frames.project_to_rotation(1e103 * r), r, atol=1e-12)  # det overflows
    assert np.allclose(frames.project_to_rotation(np.diag([1e200, 1e-200, 1.0])), np.eye(3))  # a step overflows
    assert np.allclose(frames.project_to_rotation(np.diag([1.0, 1.0, 1e-300])), np.eye(3))


def test_means_of_nearby_rotations_need_no_svd(monkeypatch):
    rng = np.random.default_rng(5)
    means = np.stack([rotation_from_vector(v) for v in rng.normal(size=(100, 3))]) * 0.9 + 0.02 * rng.normal(
        size=(100, 3, 3)
    )
    expected = nearest_rotation_by_svd(means)

    def refused(*args, **kwargs):
        raise AssertionError("the SVD was called")

    monkeypatch.setattr(frames.np.linalg, "svd", refused)
    assert np.allclose(frames.project_to_rotation(means), expected, rtol=0, atol=1e-13)


def test_a_rotation_is_its_own_nearest_rotation_bit_for_bit():
    rotations = np.stack([rotation_from_vector(v) for v in np.random.default_rng(4).normal(size=(50, 3))])
    settled = frames.project_to_rotation(rotations)  # rotation_from_vector's own rounding, settled once
    assert np.array_equal(frames.project_to_rotation(settled), settled)
    assert np.array_equal(frames.project_to_rotation(np.eye(3)), np.eye(3))


@settings(max_examples=60, deadline=None)
@given(vectors, st.lists(st.floats(0.01, 1.0), min_size=1, max_size=6))
def test_rotation_mean_of_identical_rotations_is_that_rotation(rv, weights):
    r = rotation_from_vector(rv)
    w = np.asarray(weights) / np.sum(weights)
    assert np.allclose(frames.rotation_mean(np.stack([r] * len(w)), w), r, atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.lists(vectors, min_size=2, max_size=6))
def test_rotation_mean_is_a_rotation(rvs):
    rs = np.stack([rotation_from_vector(v) for v in rvs])
    w = np.linspace(1, 2, len(rs))
    assert frames.is_rotation(frames.rotation_mean(rs, w / w.sum()))


def test_rotation_mean_of_two_turns_about_one_axis_is_the_half_turn():
    a, b = rotation_from_vector((0, 0, 0.2)), rotation_from_vector((0, 0, 0.8))
    assert np.allclose(frames.rotation_mean(np.stack([a, b]), [0.5, 0.5]), rotation_from_vector((0, 0, 0.5)))


def test_is_rotation_flags_left_handed_and_sheared():
    assert not frames.is_rotation(F)
    assert not frames.is_right_handed(F)
    assert not frames.is_rotation(np.eye(3) * 1.01)


def test_rigid_matrix_is_the_frame_without_scale_for_one_frame_or_a_stack():
    r, c = rotation_from_vector((0.4, -0.2, 1.0)), np.array([1.0, 2.0, 3.0])
    m = frames.rigid_matrix(r, c)
    assert m.shape == (4, 4) and np.array_equal(m[:3, :3], r) and np.array_equal(m[:3, 3], c)
    assert np.array_equal(m[3], [0.0, 0.0, 0.0, 1.0])
    point = np.array([0.1, -0.2, 0.3])
    assert np.allclose((m @ np.append(point, 1.0))[:3], r @ point + c)
    stack = frames.rigid_matrix(np.stack([r, np.eye(3)]), np.stack([c, -c]))
    assert stack.shape == (2, 4, 4) and np.array_equal(stack[0], m) and np.array_equal(stack[1, :3, 3], -c)
