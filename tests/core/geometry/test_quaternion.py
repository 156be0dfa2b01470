import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from devkit.toy import rotation_from_vector
from ellimann_addon.core.geometry.frames import is_rotation
from ellimann_addon.core.geometry.quaternion import quaternion_to_rotation, rotation_to_quaternion

vectors = st.tuples(*[st.floats(-3.2, 3.2)] * 3)


@settings(max_examples=200, deadline=None)
@given(vectors)
def test_round_trip_through_quaternion(rv):
    r = rotation_from_vector(rv)
    q = rotation_to_quaternion(r)
    assert np.linalg.norm(q) == pytest.approx(1.0, abs=1e-12)
    assert q[0] >= 0.0
    assert np.allclose(quaternion_to_rotation(q), r, atol=1e-12)


def test_known_quaternions():
    # 90 degrees about z: (cos 45, 0, 0, sin 45).
    rz = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    assert np.allclose(rotation_to_quaternion(rz), [np.sqrt(0.5), 0, 0, np.sqrt(0.5)])
    assert np.allclose(rotation_to_quaternion(np.eye(3)), [1, 0, 0, 0])


@pytest.mark.parametrize("axis", [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (1, -2, 3)])
def test_half_turns_keep_full_precision(axis):
    # trace = -1: the plain trace formula divides by ~0 here; Shepperd's choice must not.
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    for angle in (np.pi, np.pi - 1e-9):
        r = rotation_from_vector(axis * angle)
        q = rotation_to_quaternion(r)
        assert np.allclose(quaternion_to_rotation(q), r, atol=1e-12)
        assert abs(abs(q[1:] @ axis) - np.sin(angle / 2)) < 1e-12


def test_batched_shapes_and_agreement_with_scipy():
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(3)
    r = np.stack([rotation_from_vector(v) for v in rng.normal(size=(60, 3)) * 2]).reshape(3, 20, 3, 3)
    q = rotation_to_quaternion(r)
    assert q.shape == (3, 20, 4)
    expected = Rotation.from_matrix(r.reshape(-1, 3, 3)).as_quat()[:, [3, 0, 1, 2]]  # scipy is x, y, z, w
    expected *= np.sign(expected[:, :1])
    assert np.allclose(q.reshape(-1, 4), expected, atol=1e-12)
    assert np.all(is_rotation(quaternion_to_rotation(q)))
