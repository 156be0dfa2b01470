"""Poses: local joint rotations, forward kinematics, posed mannequins, limits, inverse and mirrored poses.

A :class:`Pose` is one local rotation per joint (24, 3, 3), in world-aligned axes at rest (SMPL's
convention: the identity everywhere is the rest pose), plus a translation of the root. Forward kinematics
gives every bone a rigid transform x -> R_j x + t_j from rest to posed; a posed mannequin is every piece moved
rigidly with its bone (``skeleton.part_bones``): the same semi-axes, its frame R_j S still in SO(3), so the
pieces stay convex and ready for simulation. Measurements stay the rest pose's (m_T is defined at rest).
"""

from dataclasses import dataclass, field

import numpy as np

from ..errors import ElliMannError
from ..mannequin.skeleton import JOINT_COUNT, JOINT_NAMES, JOINT_TWINS, PARENTS, joint_frames, limits, part_bones

SAGITTAL = np.diag([-1.0, 1.0, 1.0])
LIMIT_TOLERANCE = 1e-6  # radians a joint may pass its limit by (rounding) before it counts as beyond


@dataclass
class Pose:
    """Local rotations (24, 3, 3) in SMPL order and a root translation (3,) in metres."""

    rotations: np.ndarray = field(default_factory=lambda: np.repeat(np.eye(3)[None], JOINT_COUNT, axis=0))
    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    name: str = ""

    def __post_init__(self):
        self.rotations = np.array(self.rotations, dtype=float)
        self.translation = np.array(self.translation, dtype=float)
        if self.rotations.shape != (JOINT_COUNT, 3, 3) or self.translation.shape != (3,):
            raise ElliMannError(
                f"pose: needs ({JOINT_COUNT}, 3, 3) rotations and a 3-vector translation, got "
                f"{self.rotations.shape} and {self.translation.shape}"
            )

    def copy(self, **changes):
        values = dict(rotations=self.rotations.copy(), translation=self.translation.copy(), name=self.name)
        values.update(changes)
        return Pose(**values)

    def to_dict(self):
        """JSON: per joint its local rotation as intrinsic XYZ Euler angles in degrees (world-aligned axes)."""
        angles = np.degrees(euler_xyz(self.rotations)).tolist()
        return {
            "name": self.name,
            "translation": self.translation.tolist(),
            "euler_xyz_degrees": dict(zip(JOINT_NAMES, angles)),
        }

    @classmethod
    def from_dict(cls, data):
        """The inverse of :meth:`to_dict`; a missing joint is at rest. ElliMannError names a bad field."""
        if not isinstance(data, dict):
            raise ElliMannError("pose: must be an object with name, translation and euler_xyz_degrees")
        angles = data.get("euler_xyz_degrees") or {}
        unknown = [k for k in angles if k not in JOINT_NAMES] if isinstance(angles, dict) else None
        if unknown is None or unknown:
            what = f"unknown joint {unknown[0]!r}" if unknown else "must be an object"
            raise ElliMannError(
                f"pose.euler_xyz_degrees: {what}; joints are SMPL's ({', '.join(JOINT_NAMES[:4])}, ...)"
            )
        rotations = np.repeat(np.eye(3)[None], JOINT_COUNT, axis=0)
        for i, name in enumerate(JOINT_NAMES):
            if name in angles:
                value = _vector(angles[name], f"pose.euler_xyz_degrees.{name}")
                rotations[i] = from_euler_xyz(np.radians(value))
        translation = _vector(data.get("translation", [0.0, 0.0, 0.0]), "pose.translation")
        name = data.get("name") or ""
        if not isinstance(name, str):
            raise ElliMannError("pose.name: must be a string")
        return cls(rotations, translation, name)


def _vector(value, where):
    try:
        out = np.array(value, dtype=float)
    except (TypeError, ValueError, OverflowError, RecursionError):
        out = None
    if out is None or out.shape != (3,) or not np.all(np.isfinite(out)):
        raise ElliMannError(f"{where}: must be three finite numbers")
    return out


def rest_pose():
    return Pose(name="a_pose")


# ------------------------------------------------------------------------------------------------ rotations


def axis_angle(axis, angle):
    """Rotation matrix about a unit axis (3,) by ``angle`` radians (Rodrigues); batched over ``angle``."""
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    angle = np.asarray(angle, dtype=float)[..., None, None]
    k = np.zeros(axis.shape[:-1] + (3, 3))
    k[..., 0, 1], k[..., 0, 2], k[..., 1, 2] = -axis[..., 2], axis[..., 1], -axis[..., 0]
    k = k - np.swapaxes(k, -1, -2)
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


def from_euler_xyz(angles):
    """R = Rx(a) Ry(b) Rz(c) (intrinsic X, Y, Z; MuJoCo's three hinges in that order) from (..., 3) radians."""
    a = np.asarray(angles, dtype=float)
    rx = axis_angle(np.array([1.0, 0.0, 0.0]), a[..., 0])
    ry = axis_angle(np.array([0.0, 1.0, 0.0]), a[..., 1])
    rz = axis_angle(np.array([0.0, 0.0, 1.0]), a[..., 2])
    return rx @ ry @ rz


def euler_xyz(rotation):
    """(..., 3) radians (a, b, c) with R = Rx(a) Ry(b) Rz(c), b in [-pi/2, pi/2]."""
    r = np.asarray(rotation, dtype=float)
    b = np.arcsin(np.clip(r[..., 0, 2], -1.0, 1.0))
    a = np.arctan2(-r[..., 1, 2], r[..., 2, 2])
    c = np.arctan2(-r[..., 0, 1], r[..., 0, 0])
    return np.stack([a, b, c], axis=-1)


def rotation_between(u, v):
    """The shortest rotation taking direction u to direction v (3,)."""
    u, v = (np.asarray(x, dtype=float) / np.linalg.norm(x) for x in (u, v))
    axis = np.cross(u, v)
    sine, cosine = np.linalg.norm(axis), float(np.dot(u, v))
    if sine < 1e-12:
        if cosine > 0.0:
            return np.eye(3)
        other = np.cross(u, [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 1.0, 0.0])
        return axis_angle(other, np.pi)
    return axis_angle(axis, np.arctan2(sine, cosine))


# ------------------------------------------------------------------------------------------------ kinematics


def forward_kinematics(joints, rotations, translation=None):
    """Bone transforms of poses: joints (24, 3) at rest, rotations (..., 24, 3, 3) local, translation (..., 3).

    Returns (rotation (..., 24, 3, 3), offset (..., 24, 3), posed joints (..., 24, 3)): a point x of bone j
    at rest goes to rotation[j] @ x + offset[j].
    """
    joints = np.asarray(joints, dtype=float)
    local = np.asarray(rotations, dtype=float)
    shift = np.zeros(local.shape[:-3] + (3,)) if translation is None else np.asarray(translation, dtype=float)
    world = np.empty_like(local)
    posed = np.empty(local.shape[:-2] + (3,))
    world[..., 0, :, :] = local[..., 0, :, :]
    posed[..., 0, :] = joints[0] + shift
    for j in range(1, JOINT_COUNT):
        p = PARENTS[j]
        world[..., j, :, :] = world[..., p, :, :] @ local[..., j, :, :]
        posed[..., j, :] = posed[..., p, :] + np.einsum("...ik,k->...i", world[..., p, :, :], joints[j] - joints[p])
    offset = posed - np.einsum("...jik,jk->...ji", world, joints)
    return world, offset, posed


def bone_matrices(joints, pose):
    """(24, 4, 4): each bone's rigid motion from rest to ``pose`` (the matrix of :func:`forward_kinematics`)."""
    world, offset, _ = forward_kinematics(joints, pose.rotations, pose.translation)
    out = np.zeros((JOINT_COUNT, 4, 4))
    out[:, :3, :3], out[:, :3, 3], out[:, 3, 3] = world, offset, 1.0
    return out


def pose_arrays(joints, bones, rotation, center, pose):
    """Pieces (rotation (n, 3, 3), center (n, 3)) moved with their bones (n,) by ``pose``: (rotation, center,
    posed joints). Semi-axes do not change."""
    world, offset, posed = forward_kinematics(joints, pose.rotations, pose.translation)
    return world[bones] @ rotation, np.einsum("nij,nj->ni", world[bones], center) + offset[bones], posed


def pose_mannequin(mannequin, pose):
    """The mannequin in ``pose``: every piece moved rigidly with its bone, joints posed (a copy; the rest
    measurements are kept). ElliMannError if it has no joints."""
    joints = require_joints(mannequin)
    rotation, center, posed = pose_arrays(
        joints, part_bones(mannequin.topology), mannequin.rotation, mannequin.center, pose
    )
    return mannequin.copy(rotation=rotation, center=center, joints=posed)


def require_joints(mannequin):
    if mannequin.joints is None:
        label = f"'{mannequin.name}'" if mannequin.name else "the mannequin"
        raise ElliMannError(
            f"joints: {label} has no joints (a file from before posing, or a collection without "
            "a skeleton); posing needs them: synthesize it again or load a Reference Mannequin"
        )
    return np.asarray(mannequin.joints, dtype=float)


def inverse_pose(pose, joints):
    """The pose that takes a mannequin posed by ``pose`` (joints (24, 3) its rest joints) back to rest, applied
    to the posed mannequin (whose joints are the posed ones)."""
    world, _, posed = forward_kinematics(joints, pose.rotations, pose.translation)
    inverse_world = np.swapaxes(world, -1, -2)
    local = np.empty_like(inverse_world)
    local[0] = inverse_world[0]
    for j in range(1, JOINT_COUNT):
        local[j] = world[PARENTS[j]] @ inverse_world[j]
    # The root joint goes back to its rest position.
    return Pose(local, np.asarray(joints[0], dtype=float) - posed[0], name=f"inverse of {pose.name or 'a pose'}")


def mirror_pose(pose):
    """The pose mirrored across x = 0: left and right joints swapped, each rotation M R M (M the reflection)."""
    rotations = SAGITTAL @ pose.rotations[JOINT_TWINS] @ SAGITTAL
    return Pose(rotations, pose.translation * np.array([-1.0, 1.0, 1.0]), name=f"mirrored {pose.name}".strip())


# ------------------------------------------------------------------------------------------------ limits


@dataclass(frozen=True)
class LimitReport:
    """A joint angle beyond its range: joint name, axis ('x', 'y', 'z' of its joint frame), the angle and the
    range in degrees, and the frame of a sequence (None for a single pose)."""

    joint: str
    axis: str
    degrees: float
    low: float
    high: float
    frame: int = None

    def __str__(self):
        where = f"frame {self.frame}: " if self.frame is not None else ""
        return (
            f"{where}joint {self.joint} rotates {self.degrees:.1f} degrees about its {self.axis} axis, beyond "
            f"its range {self.low:.0f} to {self.high:.0f}"
        )


def _wrapped(angles, ranges):
    """Each angle turned by whole turns to lie nearest its range's middle."""
    middle = ranges.mean(axis=-1)
    return middle + np.mod(angles - middle + np.pi, 2.0 * np.pi) - np.pi


def _violation(angles, ranges):
    return np.sum(np.maximum(0.0, np.maximum(ranges[..., 0] - angles, angles - ranges[..., 1])), axis=-1)


def joint_angles(pose, joints):
    """(24, 3) radians: each joint's Euler angles in its joint frame (the quantities the limits bound).

    A rotation has two XYZ Euler triples, (a, b, c) and (a + pi, pi - b, c + pi); of the two, each joint takes
    the one within its limits (or nearer them), so ranges wider than 90 degrees about y (a shoulder's
    abduction) work, and each angle is taken nearest its range.
    """
    return rotation_angles(pose.rotations, joints)


def rotation_angles(rotations, joints):
    """:func:`joint_angles` of local rotations (..., 24, 3, 3): (..., 24, 3) radians."""
    frames = joint_frames(joints)
    ranges = limits(joints)
    principal = euler_xyz(np.swapaxes(frames, -1, -2) @ rotations @ frames)
    other = principal + np.array([np.pi, 0.0, np.pi])
    other[..., 1] = np.pi - principal[..., 1]
    principal, other = _wrapped(principal, ranges), _wrapped(other, ranges)
    better = _violation(other, ranges) < _violation(principal, ranges) - LIMIT_TOLERANCE
    return np.where(better[..., None], other, principal)


def limit_reports(pose, joints, frame=None):
    """Every joint angle of ``pose`` beyond its limit on a mannequin with rest ``joints``."""
    angles, ranges = joint_angles(pose, joints), limits(joints)
    out = []
    beyond = (angles < ranges[..., 0] - LIMIT_TOLERANCE) | (angles > ranges[..., 1] + LIMIT_TOLERANCE)
    for j, k in zip(*np.nonzero(beyond)):
        low, high = np.degrees(ranges[j, k])
        out.append(
            LimitReport(JOINT_NAMES[j], "xyz"[k], float(np.degrees(angles[j, k])), float(low), float(high), frame)
        )
    return out


def check_limits(pose, joints, frame=None):
    """Raise ElliMannError naming the first joint (and frame) beyond its limits."""
    reports = limit_reports(pose, joints, frame)
    if reports:
        more = f" (and {len(reports) - 1} more)" if len(reports) > 1 else ""
        named = f" {pose.name!r}" if pose.name and frame is None else ""
        raise ElliMannError(f"pose{named}: {reports[0]}{more}")


def clamp_pose(pose, joints, frame=None):
    """``pose`` with every joint angle clamped into its range, and the reports of what was clamped."""
    reports = limit_reports(pose, joints, frame)
    if not reports:
        return pose, []
    return pose.copy(rotations=clamp_rotations(pose.rotations[None], joints)[0][0]), reports


def clamp_rotations(rotations, joints):
    """Local rotations (F, 24, 3, 3) of a sequence with every joint angle clamped into its range: (clamped
    rotations, the angles before clamping (F, 24, 3) radians, where they were beyond (F, 24, 3) bool). A joint within
    its range keeps its rotation exactly."""
    frames, ranges = joint_frames(joints), limits(joints)
    angles = rotation_angles(rotations, joints)
    beyond = (angles < ranges[..., 0] - LIMIT_TOLERANCE) | (angles > ranges[..., 1] + LIMIT_TOLERANCE)
    out = np.array(rotations, dtype=float, copy=True)
    frame, joint = np.nonzero(beyond.any(axis=-1))
    if len(frame):
        kept = np.clip(angles[frame, joint], ranges[joint, :, 0], ranges[joint, :, 1])
        out[frame, joint] = frames[joint] @ from_euler_xyz(kept) @ np.swapaxes(frames[joint], -1, -2)
    return out, angles, beyond
