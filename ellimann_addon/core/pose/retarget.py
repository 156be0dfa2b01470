"""Motion from another rig (a BVH clip) onto a mannequin's skeleton, frame by frame, without Blender.

The source gives, per frame, the world rotation of each of its bones relative to its own rest
(``G = R_posed R_rest^T``) and each bone's head. Rest poses differ between rigs (a CMU or Mixamo clip rests in a
T-pose, a mannequin in the traced A-pose), so each driven joint first turns its rest direction onto the source's
(the shortest rotation ``A`` taking the direction to the next driven joint below it onto the direction between the
two source bones' heads): the mannequin then does what the clip shows, and the clip's rest frame shows as the
clip's rest pose. A joint's world rotation is ``D = S G A``, where ``S`` (the identity unless bones the mannequin
lacks turned in between, such as a twist bone) swings the result onto the clip's own direction in that frame, so
a mannequin's thighs, shins, arms and spine point where the clip's do. A joint without a source follows its parent
(``D = D_parent``); its local rotation, in the core's convention (relative to its parent, world axes at rest), is
``D_parent^T D``. A hinge (knee, elbow) can only bend about its axis, which rides on the bone above it: that bone
is first turned about its own length (its direction unchanged) until the clip's lower segment lies in the hinge's
plane, then the hinge bends onto it, so thigh and shin, upper arm and forearm all point where the clip's do with
a knee or elbow that only flexes, as far as the clip's own bend allows. The root follows the clip's pelvis scaled
by the ratio of the two hip heights: across the floor from where the mannequin stands, and up from the floor.
"""

from dataclasses import dataclass, replace

import numpy as np

from ..errors import ElliMannError
from ..geometry.quaternion import quaternion_to_rotation, rotation_to_quaternion
from ..mannequin.skeleton import JOINT_COUNT, JOINT_INDEX, PARENTS, joint_frames

FPS_RANGE = (1.0, 240.0)
FITTED_HINGES = tuple(JOINT_INDEX[f"{s}_{j}"] for s in "LR" for j in ("Knee", "Elbow"))


@dataclass
class SourceMotion:
    """A clip as sampled from its rig, in ElliMann's axes (metres, Z up, facing -Y)."""

    names: list  # the source bones, in the order of the arrays
    parents: list  # each bone's parent index (-1: a root)
    rest_heads: np.ndarray  # (k, 3) each bone's head at rest
    rotations: np.ndarray  # (F, k, 3, 3) world rotation of each bone relative to its rest
    positions: np.ndarray  # (F, k, 3) each bone's head at each frame
    fps: float
    rest_floor: float = 0.0  # z of the rest skeleton's lowest point (ends included)
    floor: float = 0.0  # z of the floor the clip moves on

    @property
    def frames(self):
        return len(self.rotations)


def shortest_rotations(a, b):
    """(..., 3, 3): the rotations of least angle taking directions ``a`` onto ``b`` (..., 3); the identity where one
    has no length, a half turn about an axis normal to ``a`` where they are opposite."""
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    shape = a.shape[:-1]
    a, b = a.reshape(-1, 3), b.reshape(-1, 3)
    lengths = np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1)
    out = np.repeat(np.eye(3)[None], len(a), axis=0)
    valid = lengths > 1e-12
    a, b = a[valid] / np.linalg.norm(a[valid], axis=-1, keepdims=True), b[valid]
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    v, c = np.cross(a, b), np.sum(a * b, axis=-1)
    k = np.zeros((len(a), 3, 3))
    k[:, 0, 1], k[:, 0, 2], k[:, 1, 2] = -v[:, 2], v[:, 1], -v[:, 0]
    k = k - np.swapaxes(k, -1, -2)
    opposite = c < -1.0 + 1e-9
    scale = 1.0 / np.where(opposite, 1.0, 1.0 + c)
    turned = np.eye(3) + k + (k @ k) * scale[:, None, None]
    if np.any(opposite):  # a half turn about any axis normal to a
        other = np.where(np.abs(a[opposite, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        axis = np.cross(a[opposite], other)
        axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
        turned[opposite] = 2.0 * axis[:, :, None] * axis[:, None, :] - np.eye(3)
    out[valid] = turned
    return out.reshape(shape + (3, 3))


def check_fps(fps):
    """ElliMannError unless ``fps`` is a frame rate a clip can be resampled to (FPS_RANGE)."""
    low, high = FPS_RANGE
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not low <= fps <= high:
        raise ElliMannError(f"fps: must be a number from {low:g} to {high:g} frames per second, got {fps!r}")
    return fps


def resample(motion, fps):
    """``motion`` at ``fps`` frames per second over the same time (rotations by spherical interpolation, heads
    linearly); ElliMannError outside FPS_RANGE."""
    check_fps(fps)
    if abs(fps - motion.fps) < 1e-9 * fps:
        return motion
    count = int(np.floor((motion.frames - 1) / motion.fps * fps + 0.01)) + 1  # a file's frame time is rounded
    where = np.arange(count) * (motion.fps / fps)
    first = np.minimum(np.floor(where).astype(int), motion.frames - 1)
    second = np.minimum(first + 1, motion.frames - 1)
    weight = (where - first)[:, None]
    q0, q1 = rotation_to_quaternion(motion.rotations[first]), rotation_to_quaternion(motion.rotations[second])
    dot = np.sum(q0 * q1, axis=-1, keepdims=True)
    q1, dot = np.where(dot < 0.0, -q1, q1), np.abs(dot)
    angle = np.arccos(np.clip(dot, -1.0, 1.0))
    small = angle < 1e-6
    sine = np.where(small, 1.0, np.sin(angle))
    w0 = np.where(small, 1.0 - weight[:, None], np.sin((1.0 - weight[:, None]) * angle) / sine)
    w1 = np.where(small, weight[:, None], np.sin(weight[:, None] * angle) / sine)
    rotations = quaternion_to_rotation(w0 * q0 + w1 * q1)
    positions = (1.0 - weight[:, None]) * motion.positions[first] + weight[:, None] * motion.positions[second]
    return replace(motion, rotations=rotations, positions=positions, fps=float(fps))


def retarget(motion, match, joints, floor=0.0):
    """(local rotations (F, 24, 3, 3), root translations (F, 3)) of a mannequin with rest ``joints`` following
    ``motion`` as ``match`` (``core.pose.bone_match.BoneMatch``) maps it; ``floor``: the z of the mannequin's
    lowest point at rest (its feet's)."""
    joints = np.asarray(joints, float)
    sources, frames = match.sources, motion.frames
    world = np.empty((frames, JOINT_COUNT, 3, 3))
    turns = {}  # {joint: (swing S (F, 3, 3), alignment A)} of the driven joints with a segment
    for joint in range(JOINT_COUNT):  # parents first
        parent = PARENTS[joint]
        if joint not in sources:
            world[:, joint] = np.eye(3) if parent < 0 else world[:, parent]
            continue
        bone, end = sources[joint], match.segment_end(joint)
        rest = None if end is None else joints[end] - joints[joint]
        clip_rest = None if end is None else motion.rest_heads[sources[end]] - motion.rest_heads[bone]
        if rest is None or np.linalg.norm(rest) < 1e-9 or np.linalg.norm(clip_rest) < 1e-9:
            ancestor = parent  # a driven leaf turns as the nearest joint above it with a segment
            while ancestor >= 0 and ancestor not in turns:
                ancestor = PARENTS[ancestor]
            swing, align = turns.get(ancestor, (np.eye(3), np.eye(3)))
            world[:, joint] = swing @ motion.rotations[:, bone] @ align
            continue
        align = shortest_rotations(rest, clip_rest)
        turned = motion.rotations[:, bone] @ align
        swing = shortest_rotations(turned @ rest, motion.positions[:, sources[end]] - motion.positions[:, bone])
        turns[joint] = (swing, align)
        world[:, joint] = swing @ turned
    for hinge in FITTED_HINGES:
        _fit_hinge(world, hinge, match, joints)
    local = world.copy()
    for joint in range(1, JOINT_COUNT):
        local[:, joint] = np.swapaxes(world[:, PARENTS[joint]], -1, -2) @ world[:, joint]
    return local, root_translations(motion, match, joints, floor)


def _fit_hinge(world, hinge, match, joints):
    """Turn the bone above ``hinge`` about its length and bend the hinge about its axis only, so that both
    segments keep the directions ``world`` gives them (as nearly as a hinge allows); in place."""
    parent, end = PARENTS[hinge], match.segment_end(hinge)
    if hinge not in match.sources or parent not in match.sources or match.segment_end(parent) != hinge or end is None:
        return
    hinge_axis, rest_lower = joint_frames(joints)[hinge][:, 0], _unit(joints[end] - joints[hinge])
    upper = world[:, parent] @ _unit(joints[hinge] - joints[parent])  # (F, 3), kept
    lower = world[:, hinge] @ rest_lower  # where the lower segment should point
    axis = world[:, parent] @ hinge_axis  # before the turn
    # Turning by t about ``upper`` keeps axis . unbent; solve axis(t) . lower = that: p cos t + q sin t = k.
    along = np.sum(axis * upper, axis=-1)
    across = axis - along[:, None] * upper
    p = np.sum(across * lower, axis=-1)
    q = np.sum(np.cross(upper, across) * lower, axis=-1)
    k = float(hinge_axis @ rest_lower) - along * np.sum(upper * lower, axis=-1)
    radius, phase = np.hypot(p, q), np.arctan2(q, p)
    spread = np.arccos(np.clip(k / np.maximum(radius, 1e-12), -1.0, 1.0))  # none exact: the nearest
    turns = np.mod(np.stack([phase - spread, phase + spread]) + np.pi, 2.0 * np.pi) - np.pi
    turn = np.take_along_axis(turns, np.argmin(np.abs(turns), axis=0)[None], axis=0)[0]
    twisted = _about(upper, turn) @ world[:, parent]
    axis, unbent = twisted @ hinge_axis, twisted @ rest_lower
    sine = np.sum(axis * np.cross(unbent, lower), axis=-1)
    cosine = np.sum(unbent * lower, axis=-1) - np.sum(axis * unbent, axis=-1) * np.sum(axis * lower, axis=-1)
    world[:, parent] = twisted
    world[:, hinge] = _about(axis, np.arctan2(sine, cosine)) @ twisted


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _about(axis, angle):
    """(F, 3, 3) rotations about unit axes (F, 3) by angles (F,)."""
    k = np.zeros(axis.shape[:-1] + (3, 3))
    k[..., 0, 1], k[..., 0, 2], k[..., 1, 2] = -axis[..., 2], axis[..., 1], -axis[..., 0]
    k = k - np.swapaxes(k, -1, -2)
    s, c = np.sin(angle)[..., None, None], np.cos(angle)[..., None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


def root_translations(motion, match, joints, floor=0.0):
    """(F, 3): the root's translation from rest following the clip's pelvis (its root where no bone drives the
    pelvis), scaled by the ratio of the hip heights (each above its own floor): horizontally from where the
    mannequin stands at the clip's first frame, vertically from the floor."""
    pelvis = match.sources.get(0, motion.parents.index(-1))
    clip_height = motion.rest_heads[pelvis, 2] - motion.rest_floor
    height = joints[0, 2] - floor
    scale = height / clip_height if clip_height > 1e-6 else 1.0
    path = motion.positions[:, pelvis]
    out = np.empty((motion.frames, 3))
    out[:, :2] = scale * (path[:, :2] - path[:1, :2])
    out[:, 2] = floor + scale * (path[:, 2] - motion.floor) - joints[0, 2]
    return out
