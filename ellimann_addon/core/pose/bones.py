"""The armature a Blender (or any bone-based) rig needs for a mannequin's joints, without Blender.

Bones sit at the joints (head = joint centre). Each bone's rest frame is its joint's limit frame with
the axes relabelled (a signed permutation) so that the bone's Y axis, the one rigs point along the
limb, is the frame axis closest to the direction to its child joint. With that choice a rotation
limit given as Euler ranges in the limit frame is *exactly* a box of Euler ranges in the bone's own
axes (another axis order, some signs flipped), which is what Blender's Limit Rotation constraint
enforces; a bone whose limit frame is the world's points along a world axis.

Pose convention (the core's, ``core.pose.kinematics``): per joint a rotation relative to its parent, in the joint's
rest axes (the world's), identity = rest. A bone's own rotation (Blender's pose-bone basis) is that
rotation seen in the bone's rest frame: ``B.T @ L @ B``.
"""

from dataclasses import dataclass

import numpy as np

AXES = "XYZ"
LEAF_LENGTH = 0.35  # a bone without a child is this fraction of its parent's length (hands, feet, head)
MIN_LENGTH = 0.02  # m: no bone shorter (Blender removes zero-length bones)


@dataclass(frozen=True)
class BoneLimit:
    """A Limit Rotation constraint in a bone's own axes: the Euler order (Blender's spelling: 'XZY'
    applies X first) and, per bone axis X, Y, Z, (min, max) in radians, or None where it is free."""

    euler_order: str
    ranges: tuple


@dataclass(frozen=True)
class Bone:
    name: str
    parent: int  # index, -1 for the root
    head: np.ndarray  # (3,) the joint centre, m
    tail: np.ndarray  # (3,) head + length * the bone's Y axis
    frame: np.ndarray  # (3, 3) columns = the bone's X, Y, Z axes in the world, at rest


def limb_directions(joints, parents, preferred_child=None):
    """(24, 3) unit direction from each joint to its child (the preferred one where it has several), and
    each bone's length; a leaf continues its parent's direction at LEAF_LENGTH of its length."""
    joints = np.asarray(joints, dtype=float)
    count = len(joints)
    preferred_child = preferred_child or {}
    children = {i: [j for j in range(count) if parents[j] == i] for i in range(count)}
    directions, lengths = np.zeros((count, 3)), np.zeros(count)
    for i in range(count):  # parents come before their children (SMPL order)
        kids = children[i]
        if kids:
            child = preferred_child.get(i, kids[0]) if len(kids) > 1 else kids[0]
            offset = joints[child] - joints[i]
            lengths[i] = max(np.linalg.norm(offset), MIN_LENGTH)
            directions[i] = offset / np.linalg.norm(offset) if np.linalg.norm(offset) > 0 else (0.0, 0.0, 1.0)
        else:
            parent = parents[i]
            directions[i] = directions[parent] if parent >= 0 else (0.0, 0.0, 1.0)
            lengths[i] = max(LEAF_LENGTH * lengths[parent] if parent >= 0 else MIN_LENGTH, MIN_LENGTH)
    return directions, lengths


def bone_axes(limit_frame, direction):
    """(3, 3) signed permutation P: the bone frame is ``limit_frame @ P``; its Y axis (column 1) is the
    limit-frame axis closest to ``direction`` and its X axis the remaining one closest to world X."""
    frame = np.asarray(limit_frame, dtype=float)
    along = frame.T @ np.asarray(direction, dtype=float)
    y_axis = int(np.argmax(np.abs(along)))
    y_sign = 1.0 if along[y_axis] >= 0 else -1.0
    rest = [k for k in range(3) if k != y_axis]
    world_x = frame.T @ np.array((1.0, 0.0, 0.0))
    x_axis = max(rest, key=lambda k: (abs(world_x[k]), -k))
    x_sign = 1.0 if world_x[x_axis] >= 0 else -1.0
    permutation = np.zeros((3, 3))
    permutation[x_axis, 0], permutation[y_axis, 1] = x_sign, y_sign
    permutation[:, 2] = np.cross(permutation[:, 0], permutation[:, 1])  # right-handed
    return permutation


def layout_bones(names, joints, parents, limit_frames=None, preferred_child=None):
    """The bones of a skeleton: one per joint, head at the joint, frames as the module says."""
    joints = np.asarray(joints, dtype=float)
    count = len(joints)
    limit_frames = np.broadcast_to(np.eye(3), (count, 3, 3)) if limit_frames is None else np.asarray(limit_frames)
    directions, lengths = limb_directions(joints, parents, preferred_child)
    bones = []
    for i in range(count):
        frame = limit_frames[i] @ bone_axes(limit_frames[i], directions[i])
        bones.append(Bone(names[i], int(parents[i]), joints[i].copy(), joints[i] + lengths[i] * frame[:, 1], frame))
    return bones


def bone_limit(bone, limit_frame, ranges, euler_order="ZYX"):
    """The Limit Rotation of ``bone`` for limits given in ``limit_frame``'s axes: ``ranges`` per frame axis
    (lo, hi) in radians or None (free), decomposed in ``euler_order`` (Blender's spelling: the default
    'ZYX' is R = Rx(a) Ry(b) Rz(c), the core's intrinsic X, Y, Z of ``core.mannequin.skeleton.limits``).

    The bone frame is the limit frame relabelled (B = F P): frame axis k is bone axis j with sign s,
    so a rotation by t about frame axis k is one by s t about bone axis j and the order's letters map.
    """
    permutation = np.asarray(limit_frame, dtype=float).T @ bone.frame  # P, exactly a signed permutation
    bone_axis = {k: int(np.argmax(np.abs(permutation[k]))) for k in range(3)}
    sign = {k: float(np.sign(permutation[k, bone_axis[k]])) for k in range(3)}
    bone_ranges = [None, None, None]
    for k, span in enumerate(ranges):
        if span is None:
            continue
        lo, hi = span[0] * sign[k], span[1] * sign[k]
        bone_ranges[bone_axis[k]] = (float(min(lo, hi)), float(max(lo, hi)))
    order = "".join(AXES[bone_axis[AXES.index(letter)]] for letter in euler_order)
    return BoneLimit(order, tuple(bone_ranges))


def bone_rotations(frames, local_rotations):
    """(n, 3, 3) bone-basis rotations ``B.T @ L @ B`` of core local rotations ``L`` (n, 3, 3), bones' frames
    ``frames`` (n, 3, 3); ``local_rotations`` may carry leading axes (frames of an animation)."""
    frames = np.asarray(frames, dtype=float)
    return np.einsum("nji,...njk,nkl->...nil", frames, np.asarray(local_rotations, dtype=float), frames)


def root_location(frame, translation):
    """A root bone's location channel (its own axes) for a world translation of the root joint."""
    return np.asarray(translation, dtype=float) @ np.asarray(frame, dtype=float)
