"""core.pose.bones (an armature's layout for a skeleton), the shortest rotations retargeting turns bones by and a
drape's motion, without Blender (clips retargeted: test_motion_clips.py)."""

import numpy as np
import pytest

from ellimann_addon.core.pose.bones import bone_axes, bone_limit, bone_rotations, layout_bones, root_location
from ellimann_addon.core.pose.kinematics import axis_angle
from ellimann_addon.core.pose.retarget import shortest_rotations

AXES = np.eye(3)


def random_rotation(rng):
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def blender_euler(order, angles_by_axis):
    """A rotation from Euler angles in Blender's spelling: 'XZY' applies X first, so R = Ry Rz Rx."""
    rotation = np.eye(3)
    for letter in order:
        axis = "XYZ".index(letter)
        rotation = axis_angle(AXES[axis], angles_by_axis[axis]) @ rotation
    return rotation


@pytest.mark.parametrize("seed", range(20))
def test_bone_frames_are_the_limit_frames_relabelled(seed):
    rng = np.random.default_rng(seed)
    frame, direction = random_rotation(rng), rng.normal(size=3)
    permutation = bone_axes(frame, direction)
    assert np.allclose(np.abs(permutation).sum(axis=0), 1.0) and np.allclose(np.abs(permutation).sum(axis=1), 1.0)
    assert np.isclose(np.linalg.det(permutation), 1.0)  # right-handed: still in SO(3)
    bone = frame @ permutation
    assert np.isclose(bone[:, 1] @ direction, np.abs(frame.T @ direction).max())  # Y: the closest axis, toward it


@pytest.mark.parametrize("seed", range(20))
def test_a_limit_in_the_limit_frame_is_a_box_in_the_bones_axes(seed):
    """Euler angles (a, b, c) of R = Rx(a) Ry(b) Rz(c) in the limit frame are, in the bone's own axes and the
    constraint's order, the same angles with signs: Blender's Limit Rotation bounds exactly what the core does."""
    rng = np.random.default_rng(100 + seed)
    frame, direction = random_rotation(rng), rng.normal(size=3)
    joints = np.array([[0.0, 0.0, 0.0], direction / np.linalg.norm(direction)])
    bone = layout_bones(["A", "B"], joints, [-1, 0], limit_frames=np.stack([frame, frame]))[0]
    angles = rng.uniform(-1.2, 1.2, size=3)
    limit = bone_limit(bone, frame, [(a - 0.1, a + 0.1) for a in angles])
    local = (
        frame
        @ axis_angle(AXES[0], angles[0])
        @ axis_angle(AXES[1], angles[1])
        @ axis_angle(AXES[2], angles[2])
        @ frame.T
    )
    basis = bone_rotations(bone.frame[None], local[None])[0]
    centres = np.array([(lo + hi) / 2.0 for lo, hi in limit.ranges])
    assert np.allclose(blender_euler(limit.euler_order, centres), basis, atol=1e-12)


def test_bones_sit_at_the_joints_and_point_at_their_child():
    joints = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 0.5], [0.0, -0.2, 0.5]])
    bones = layout_bones(["hip", "knee", "toe"], joints, [-1, 0, 1])
    assert np.allclose([b.head for b in bones], joints)
    assert np.allclose(bones[0].tail, [0.0, 0.0, 0.5]) and np.allclose(bones[1].tail, [0.0, -0.2, 0.5])
    assert np.allclose(bones[2].frame[:, 1], [0.0, -1.0, 0.0])  # a leaf continues its parent's direction
    assert all(np.allclose(b.frame.T @ b.frame, np.eye(3)) for b in bones)


def test_root_location_and_bone_rotations_invert_the_bone_frame():
    rng = np.random.default_rng(7)
    frame, rotation, shift = random_rotation(rng), random_rotation(rng), rng.normal(size=3)
    assert np.allclose(frame @ root_location(frame, shift), shift)
    assert np.allclose(frame @ bone_rotations(frame[None], rotation[None])[0] @ frame.T, rotation)


def test_shortest_rotations():
    a = np.array([(1, 0, 0), (0, 0, 1), (1, 2, 3), (1, 0, 0), (0, 2, 0), (0, 0, 0)], dtype=float)
    b = np.array([(0, 1, 0), (0, 0, -1), (-3, 1, 0.5), (1, 0, 0), (0, -1, 0), (1, 0, 0)], dtype=float)
    rotations = shortest_rotations(a, b)
    for rotation, u, v in zip(rotations[:5], a, b):
        assert np.allclose(rotation @ (u / np.linalg.norm(u)), v / np.linalg.norm(v))
        assert np.allclose(rotation.T @ rotation, np.eye(3)) and np.isclose(np.linalg.det(rotation), 1.0)
    assert np.allclose(rotations[5], np.eye(3))  # no direction: no turn
    turned = shortest_rotations([1.0, 0.0, 0.0], [1.0, 1.0, 0.0])  # the least angle: about z only
    assert np.allclose(turned, axis_angle([0.0, 0.0, 1.0], np.pi / 4))


def test_a_drape_motion_starts_at_rest_reaches_the_pose_and_loops_with_the_drift():
    from ellimann_addon.core.pose.kinematics import Pose
    from ellimann_addon.core.pose.motion import arms_out, drape_motion, rotation_fraction

    rng = np.random.default_rng(3)
    poses = [Pose(np.stack([random_rotation(rng) for _ in range(24)]), rng.normal(size=3)) for _ in range(3)]
    motion = drape_motion(poses, 10, 4, loop=True, drift=(0.0, -1.0, 0.0))
    assert np.allclose(motion[0].rotations, np.eye(3)) and np.allclose(motion[0].translation, 0.0)
    assert np.allclose(motion[4].rotations, poses[0].rotations)
    assert np.allclose(motion[7].rotations, poses[0].rotations)  # frame 8: the second cycle's first
    assert np.allclose(motion[7].translation, poses[0].translation + (0.0, -1.0, 0.0))
    half = rotation_fraction(poses[0].rotations[5], 0.5)
    assert np.allclose(half @ half, poses[0].rotations[5])  # halfway along the arc
    out = arms_out(poses, 15.0)[0]
    assert np.allclose(np.delete(out.rotations, [16, 17], axis=0), np.delete(poses[0].rotations, [16, 17], axis=0))
    turn = out.rotations[16] @ poses[0].rotations[16].T
    assert np.isclose(np.degrees(np.arccos((np.trace(turn) - 1) / 2)), 15.0)
