"""A drape's motion: from the rest pose into a pose or a motion, frame by frame (numpy only).

A garment is built around the rest pose; a cloth whose collider jumps to another pose in one frame
tunnels through it. So a drape's body starts at rest, turns into the first pose over ``settle``
frames (each joint's rotation a fraction of the way along its shortest arc, the root translated
linearly), then holds a still pose or plays a motion, a looping one again and again (each cycle
starting where the last one ended, shifted by the loop's drift, e.g. the walk's stride).
"""

import numpy as np

from ..mannequin.skeleton import JOINT_INDEX
from .kinematics import Pose, axis_angle, clamp_pose
from .standard import MOTIONS, standard_motion


def rotation_fraction(rotation, fraction):
    """The rotation ``fraction`` of the way from the identity to ``rotation`` (3, 3) along its shortest arc."""
    rotation = np.asarray(rotation, dtype=float)
    cosine = np.clip((np.trace(rotation) - 1.0) / 2.0, -1.0, 1.0)
    angle = float(np.arccos(cosine))
    if angle < 1e-12:
        return np.eye(3)
    if np.pi - angle < 1e-6:  # half a turn: the axis from the symmetric part
        axis = np.sqrt(np.clip((np.diag(rotation) + 1.0) / 2.0, 0.0, None))
        k = int(np.argmax(axis))
        axis = (rotation[:, k] + np.eye(3)[k]) / np.linalg.norm(rotation[:, k] + np.eye(3)[k])
    else:
        axis = np.array(
            [rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0], rotation[1, 0] - rotation[0, 1]]
        ) / (2.0 * np.sin(angle))
    return axis_angle(axis, fraction * angle)


def drape_motion(poses, frames, settle, loop=False, drift=None):
    """``frames`` poses: rest at frame 1, ``poses[0]`` at frame ``settle`` + 1, then ``poses`` in turn (a still
    pose held; a ``loop`` repeated, each cycle shifted by ``drift`` (3,), default none)."""
    if frames < 1 or settle < 0 or not poses:
        raise ValueError("drape_motion needs frames >= 1, settle >= 0 and at least one pose")
    first = poses[0]
    out = []
    for frame in range(min(frames, settle + 1)):
        t = frame / settle if settle else 1.0
        rotations = np.array([rotation_fraction(r, t) for r in first.rotations])
        out.append(Pose(rotations, t * first.translation, name=f"settling {frame + 1}"))
    shift = np.zeros(3) if drift is None else np.asarray(drift, dtype=float)
    index = 1
    while len(out) < frames:
        cycle, position = divmod(index, len(poses)) if loop else (0, min(index, len(poses) - 1))
        pose = poses[position]
        out.append(pose.copy(translation=pose.translation + cycle * shift))
        index += 1
    return out


def arms_out(poses, degrees):
    """``poses`` with both arms turned ``degrees`` further out from the body at the shoulder (abduction, in the
    collar's axes, mirrored: the left arm about -Y, the right about +Y), everything else as it was."""
    left, right = JOINT_INDEX["L_Shoulder"], JOINT_INDEX["R_Shoulder"]
    turn = {
        left: axis_angle(np.array([0.0, -1.0, 0.0]), np.radians(degrees)),
        right: axis_angle(np.array([0.0, 1.0, 0.0]), np.radians(degrees)),
    }
    out = []
    for pose in poses:
        rotations = pose.rotations.copy()
        for joint, rotation in turn.items():
            rotations[joint] = rotation @ rotations[joint]
        out.append(pose.copy(rotations=rotations))
    return out


def loop_drift(poses):
    """The root's shift from one cycle to the next of a looping motion: along -Y (the walking direction), the
    step of its last two frames extrapolated to the next cycle's first; nothing sideways or up."""
    if len(poses) < 2:
        return np.zeros(3)
    last, before = poses[-1].translation, poses[-2].translation
    return np.array([0.0, 2.0 * last[1] - before[1] - poses[0].translation[1], 0.0])


def clamped_motion(name, joints):
    """(poses, clamp reports, whether it loops) of the standard pose or motion ``name`` on a mannequin with
    rest ``joints``, every joint angle clamped into its range (ElliMannError for an unknown name)."""
    poses = standard_motion(name, joints)
    clamped = [clamp_pose(p, joints, frame=i + 1 if name in MOTIONS else None) for i, p in enumerate(poses)]
    return [p for p, _ in clamped], [r for _, found in clamped for r in found], name in MOTIONS
