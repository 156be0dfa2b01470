"""Kinematics: closed forms (a 90-degree elbow, the standard poses' geometry), pose and inverse, mirrored poses,
rigidity of the pieces, limits and clamping, on the shipped Reference Mannequins' own joints."""

import numpy as np
import pytest

from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.geometry.ellipsoid import axis_extent, shape_matrix
from ellimann_addon.core.geometry.frames import is_rotation
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.skeleton import (
    BASE_LIMITS,
    JOINT_COUNT,
    JOINT_INDEX,
    JOINT_NAMES,
    JOINT_TWINS,
    joint_frames,
    limits,
    part_bones,
)
from ellimann_addon.core.pose import kinematics as kinematics
from ellimann_addon.core.pose import standard as poses
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER, REFERENCE_NAMES

J = JOINT_INDEX
STEMS = ("base_mannequin",) + REFERENCE_NAMES


@pytest.fixture(scope="module", params=STEMS)
def mannequin(request):
    return Mannequin.load(REFERENCE_FOLDER / f"{request.param}.json")


@pytest.fixture(scope="module")
def average():
    return Mannequin.load(REFERENCE_FOLDER / "average.json")


def random_pose(joints, seed, share=0.8):
    """A pose with every joint at a random angle within ``share`` of its range (seeded)."""
    rng = np.random.default_rng(seed)
    ranges = limits(joints)
    middle, half = ranges.mean(axis=-1), 0.5 * np.diff(ranges, axis=-1)[..., 0]
    angles = middle + share * half * rng.uniform(-1.0, 1.0, (JOINT_COUNT, 3))
    frames = joint_frames(joints)
    rotations = frames @ kinematics.from_euler_xyz(angles) @ np.swapaxes(frames, -1, -2)
    return kinematics.Pose(rotations, rng.uniform(-0.2, 0.2, 3), name=f"random {seed}")


def posed_joint(mannequin, pose, name):
    return kinematics.forward_kinematics(mannequin.joints, pose.rotations, pose.translation)[2][J[name]]


def test_a_90_degree_elbow_bend_puts_the_forearm_square_to_the_upper_arm_in_front(average):
    joints = average.joints
    straight = poses.t_pose(joints)
    shoulder, elbow, wrist = (posed_joint(average, straight, n) for n in ("L_Shoulder", "L_Elbow", "L_Wrist"))
    world = kinematics.forward_kinematics(joints, straight.rotations)[0]
    hinge = world[J["L_Shoulder"]] @ joint_frames(joints)[J["L_Elbow"]][:, 0]  # the hinge axis, T-posed
    bent = straight.copy()
    flex = kinematics.axis_angle(joint_frames(joints)[J["L_Elbow"]][:, 0], np.pi / 2)
    bent.rotations[J["L_Elbow"]] = flex @ straight.rotations[J["L_Elbow"]]
    moved = posed_joint(average, bent, "L_Wrist")
    # Rodrigues about the posed hinge through the elbow, by hand: w' = e + cos(t) v + sin(t) k x v + (1-cos t)(k.v)k
    v, k = wrist - elbow, hinge / np.linalg.norm(hinge)
    expected = elbow + np.cross(k, v) + np.dot(k, v) * k
    assert np.allclose(moved, expected, atol=1e-12)
    forearm, upper = moved - elbow, elbow - shoulder
    assert abs(np.dot(forearm, upper)) < 1e-12 * np.linalg.norm(upper) * np.linalg.norm(forearm)  # square
    assert np.isclose(np.linalg.norm(forearm), np.linalg.norm(wrist - elbow), atol=1e-12)
    assert -forearm[1] > 0.95 * np.linalg.norm(forearm)  # flexion brings the forearm to the front (-Y)
    assert kinematics.limit_reports(bent, joints) == []


def test_t_pose_arms_horizontal_and_straight_nothing_else_moves(mannequin):
    pose = poses.t_pose(mannequin.joints)
    for side, sign in (("L", 1.0), ("R", -1.0)):
        s, e, w = (posed_joint(mannequin, pose, f"{side}_{n}") for n in ("Shoulder", "Elbow", "Wrist"))
        for a, b in ((s, e), (e, w)):
            d = (b - a) / np.linalg.norm(b - a)
            assert np.allclose(d, [sign, 0.0, 0.0], atol=1e-12)
    moved = {J[f"{s}_{n}"] for s in "LR" for n in ("Shoulder", "Elbow")}
    still = [j for j in range(JOINT_COUNT) if j not in moved]
    assert np.allclose(pose.rotations[still], np.eye(3), atol=0.0)


def test_attention_arms_hang_five_degrees_from_vertical(mannequin):
    pose = poses.attention(mannequin.joints)
    for side in "LR":
        s, w = (posed_joint(mannequin, pose, f"{side}_{n}") for n in ("Shoulder", "Wrist"))
        d = (w - s) / np.linalg.norm(w - s)
        assert np.isclose(np.degrees(np.arccos(-d[2])), poses.ATTENTION_DEGREES, atol=1e-9)
        assert abs(d[1]) < 1e-12 and np.sign(d[0]) == (1.0 if side == "L" else -1.0)


def test_sit_thighs_horizontal_shins_vertical_feet_flat_on_the_floor(mannequin):
    pose = poses.sit(mannequin.joints)
    for side in "LR":
        hip, knee, ankle = (posed_joint(mannequin, pose, f"{side}_{n}") for n in ("Hip", "Knee", "Ankle"))
        assert abs(knee[2] - hip[2]) < 1e-12 and knee[1] < hip[1]  # thigh horizontal, forward
        assert np.allclose((ankle - knee)[:2], 0.0, atol=1e-12)  # shin vertical
        assert np.isclose(ankle[2], mannequin.joints[J[f"{side}_Ankle"], 2], atol=1e-12)
    posed = kinematics.pose_mannequin(mannequin, pose)
    feet = [i for i, b in enumerate(part_bones(mannequin.topology)) if JOINT_NAMES[b] in ("L_Ankle", "L_Foot")]
    bottom = posed.center[feet, 2] - axis_extent(posed.rotation[feet], posed.semi_axes[feet], 2)
    rest = mannequin.center[feet, 2] - axis_extent(mannequin.rotation[feet], mannequin.semi_axes[feet], 2)
    assert np.allclose(bottom, rest, atol=1e-12)  # feet as at rest: flat, on the floor


def test_standard_poses_and_the_walk_are_within_limits(mannequin):
    joints = mannequin.joints
    for name in poses.POSE_NAMES:
        for index, frame in enumerate(poses.standard_motion(name, joints)):
            assert kinematics.limit_reports(frame, joints) == [], (name, index)


def test_walk_loops_one_stride_per_second_at_24_fps(average):
    two = poses.walk(average.joints, fps=24, seconds=2.0)
    assert len(poses.walk(average.joints)) == 24
    assert np.allclose(two[24].rotations, two[0].rotations, atol=1e-12)
    stride = two[24].translation - two[0].translation
    assert stride[1] < -0.5 and abs(stride[0]) < 1e-12 and abs(stride[2]) < 1e-12
    # the legs alternate: half a cycle later the left hip is where the right one was, mirrored
    assert np.allclose(two[12].rotations[J["L_Hip"]], kinematics.mirror_pose(two[0]).rotations[J["L_Hip"]], atol=1e-12)


@pytest.mark.parametrize("seed", range(5))
def test_a_pose_then_its_inverse_is_the_rest_pose(average, seed):
    pose = random_pose(average.joints, seed)
    posed = kinematics.pose_mannequin(average, pose)
    back = kinematics.pose_mannequin(posed, kinematics.inverse_pose(pose, average.joints))
    for attr in ("rotation", "center", "semi_axes", "joints"):
        assert np.abs(getattr(back, attr) - getattr(average, attr)).max() < 1e-9, attr
    assert np.abs(posed.center - average.center).max() > 0.05  # it did move


def _mirrored(mannequin):
    """The mannequin's sagittal mirror image as ellipsoid sets (shape matrices), centres, joints."""
    flip = np.diag([-1.0, 1.0, 1.0])
    twin = mannequin.topology.twin_indices
    shape = shape_matrix(mannequin.rotation, mannequin.semi_axes)
    return flip @ shape[twin] @ flip, mannequin.center[twin] * [-1, 1, 1], mannequin.joints[JOINT_TWINS] * [-1, 1, 1]


@pytest.mark.parametrize("seed", range(3))
def test_mirrored_poses_give_mirrored_mannequins(average, seed):
    pose = random_pose(average.joints, 10 + seed)
    a = kinematics.pose_mannequin(average, pose)
    b = kinematics.pose_mannequin(average, kinematics.mirror_pose(pose))
    shape, center, joints = _mirrored(a)
    assert np.abs(shape_matrix(b.rotation, b.semi_axes) - shape).max() < 1e-12
    assert np.abs(b.center - center).max() < 1e-12 and np.abs(b.joints - joints).max() < 1e-12
    assert np.abs(kinematics.mirror_pose(kinematics.mirror_pose(pose)).rotations - pose.rotations).max() == 0.0
    # the mirrored pose is within the mirrored limits exactly when the pose is within its own
    assert kinematics.limit_reports(kinematics.mirror_pose(pose), average.joints) == []


def test_limits_of_the_right_side_mirror_the_left(average):
    ranges = limits(average.joints)
    mirrored = ranges[JOINT_TWINS].copy()
    mirrored[:, 1:] = -mirrored[:, 1:, ::-1]
    assert np.allclose(ranges, mirrored, atol=1e-12)
    assert np.all(BASE_LIMITS[..., 0] <= BASE_LIMITS[..., 1])


@pytest.mark.parametrize("seed", range(3))
def test_posing_is_rigid(mannequin, seed):
    posed = kinematics.pose_mannequin(mannequin, random_pose(mannequin.joints, 20 + seed))
    assert np.array_equal(posed.semi_axes, mannequin.semi_axes)
    assert np.all(is_rotation(posed.rotation, 1e-12))
    bones = part_bones(mannequin.topology)
    for a in range(len(mannequin)):  # distances between pieces of one bone, and to its joint, are kept
        same = np.flatnonzero(bones == bones[a])
        rest = np.linalg.norm(mannequin.center[same] - mannequin.center[a], axis=1)
        assert np.allclose(np.linalg.norm(posed.center[same] - posed.center[a], axis=1), rest, atol=1e-12)
        joint = bones[a]
        assert np.isclose(
            np.linalg.norm(posed.center[a] - posed.joints[joint]),
            np.linalg.norm(mannequin.center[a] - mannequin.joints[joint]),
            atol=1e-12,
        )


def test_euler_angles_round_trip():
    rng = np.random.default_rng(3)
    angles = rng.uniform([-3.0, -1.5, -3.0], [3.0, 1.5, 3.0], (200, 3))
    assert np.allclose(kinematics.euler_xyz(kinematics.from_euler_xyz(angles)), angles, atol=1e-12)
    r = kinematics.from_euler_xyz(angles)
    assert np.allclose(r[:, 0, 2], np.sin(angles[:, 1]))  # R = Rx Ry Rz: entry (0, 2) is sin(b)


def test_beyond_limits_is_named_clamped_and_refused(average):
    joints = average.joints
    pose = poses.sit(joints)
    pose.rotations[J["R_Knee"]] = kinematics.axis_angle([1.0, 0.0, 0.0], np.radians(175.0))
    reports = kinematics.limit_reports(pose, joints, frame=7)
    assert [(r.joint, r.axis, r.frame) for r in reports] == [("R_Knee", "x", 7)]
    assert "frame 7" in str(reports[0]) and "R_Knee" in str(reports[0])
    clamped, said = kinematics.clamp_pose(pose, joints, frame=7)
    assert said == reports and kinematics.limit_reports(clamped, joints) == []
    high = np.degrees(limits(joints)[J["R_Knee"], 0, 1])
    assert np.isclose(np.degrees(kinematics.joint_angles(clamped, joints)[J["R_Knee"], 0]), high, atol=1e-9)
    untouched = [j for j in range(JOINT_COUNT) if j != J["R_Knee"]]
    assert np.array_equal(clamped.rotations[untouched], pose.rotations[untouched])
    with pytest.raises(ElliMannError, match="R_Knee"):
        kinematics.check_limits(pose, joints)


def test_a_mannequin_without_joints_is_refused_in_one_line(average):
    with pytest.raises(ElliMannError, match="has no joints") as error:
        kinematics.pose_mannequin(average.copy(joints=None), kinematics.rest_pose())
    assert "\n" not in str(error.value)
    with pytest.raises(ElliMannError, match="unknown pose 'dance'"):
        poses.standard_pose("dance", average.joints)


def test_pose_json_round_trip(average):
    pose = random_pose(average.joints, 4)
    back = kinematics.Pose.from_dict(pose.to_dict())
    assert np.allclose(back.rotations, pose.rotations, atol=1e-12) and np.allclose(back.translation, pose.translation)
    with pytest.raises(ElliMannError, match="unknown joint 'Tail'"):
        kinematics.Pose.from_dict({"euler_xyz_degrees": {"Tail": [0, 0, 0]}})
    with pytest.raises(ElliMannError, match="L_Knee"):
        kinematics.Pose.from_dict({"euler_xyz_degrees": {"L_Knee": [0, "x", 0]}})
