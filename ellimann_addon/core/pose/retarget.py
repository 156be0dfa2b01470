"""Motion from another rig (a BVH clip) onto a mannequin's skeleton, frame by frame, without Blender.

The source gives, per frame, the world rotation of each of its bones relative to its own rest
(``G = R_posed R_rest^T``) and its root's position. Rest poses differ between rigs (a CMU or Mixamo
clip rests in a T-pose, a mannequin in the traced A-pose), so each mapped joint first turns its rest
direction onto the source's (the shortest rotation ``A`` taking the direction to its child joint onto
the source bone's): the mannequin then does what the clip shows, and the clip's rest frame shows as
the clip's rest pose. A joint's world rotation is ``D = G A``; an unmapped joint follows its parent
(``D = D_parent``); its local rotation, in the core's convention (relative to its parent, world axes
at rest), is ``D_parent^T D``. The root moves by the clip's root displacement, scaled by the ratio of
the two hip heights.
"""

from dataclasses import dataclass

import numpy as np

from ..errors import ElliMannError


@dataclass
class SourceMotion:
    """A clip as sampled from its rig, in ElliMann's axes (metres, Z up, facing -Y)."""

    names: list  # the source bones, in the order of the arrays
    rest_heads: np.ndarray  # (k, 3) each bone's head at rest
    rotations: np.ndarray  # (F, k, 3, 3) world rotation of each bone relative to its rest
    root_positions: np.ndarray  # (F, 3) the source root's head at each frame
    fps: float


def shortest_rotation(a, b):
    """The rotation (3, 3) of least angle taking unit direction ``a`` onto unit direction ``b``."""
    a = np.asarray(a, float) / np.linalg.norm(a)
    b = np.asarray(b, float) / np.linalg.norm(b)
    axis = np.cross(a, b)
    sine, cosine = np.linalg.norm(axis), float(np.dot(a, b))
    if sine < 1e-12:
        if cosine > 0:
            return np.eye(3)
        other = np.eye(3)[int(np.argmin(np.abs(a)))]  # half a turn about any axis normal to a
        axis = np.cross(a, other) / np.linalg.norm(np.cross(a, other))
        return 2.0 * np.outer(axis, axis) - np.eye(3)
    k = axis / sine
    cross = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + sine * cross + (1.0 - cosine) * cross @ cross


def matched_joints(joint_names, source_names, name_map):
    """{joint index: source index} for the joints the map names and the clip has."""
    index = {name: i for i, name in enumerate(source_names)}
    return {
        j: index[source]
        for source, joint in name_map.items()
        if source in index
        for j in [joint_names.index(joint)]
        if joint in joint_names
    }


def retarget(motion, joint_names, joints, parents, name_map, preferred_child=None):
    """(local rotations (F, n, 3, 3), root translations (F, 3)) of the mannequin following ``motion``.

    ``name_map``: {source bone name: joint name}. Raises ElliMannError naming the clip's bones when
    none of them is in the map.
    """
    matched = matched_joints(joint_names, motion.names, name_map)
    if not matched:
        shown = ", ".join(motion.names[:4]) + (", ..." if len(motion.names) > 4 else "")
        raise ElliMannError(
            f"bones: none of the clip's {len(motion.names)} bones ({shown}) is in the bone-name "
            f"map (MakeHuman/CMU or Mixamo names)"
        )
    joints = np.asarray(joints, float)
    count, frames = len(joint_names), len(motion.rotations)
    preferred_child = preferred_child or {}
    children = {i: [j for j in range(count) if parents[j] == i] for i in range(count)}
    alignment = {}
    for joint, source in matched.items():
        kids = [k for k in children[joint] if k in matched]
        if not kids:
            continue
        child = preferred_child.get(joint) if preferred_child.get(joint) in kids else kids[0]
        target_direction = joints[child] - joints[joint]
        source_direction = motion.rest_heads[matched[child]] - motion.rest_heads[source]
        if np.linalg.norm(target_direction) > 1e-9 and np.linalg.norm(source_direction) > 1e-9:
            alignment[joint] = shortest_rotation(target_direction, source_direction)
    world = np.empty((frames, count, 3, 3))
    for joint in range(count):  # parents first
        parent = parents[joint]
        if joint in matched:
            align = alignment.get(joint, np.eye(3) if parent < 0 else None)
            if align is None:  # a mapped leaf: keep the alignment its parent had
                align = _inherited_alignment(joint, parents, alignment)
            world[:, joint] = motion.rotations[:, matched[joint]] @ align
        else:
            world[:, joint] = np.eye(3) if parent < 0 else world[:, parent]
    local = world.copy()
    for joint in range(count):
        if parents[joint] >= 0:
            local[:, joint] = np.swapaxes(world[:, parents[joint]], -1, -2) @ world[:, joint]
    root = next(i for i in range(count) if parents[i] < 0)
    translations = np.zeros((frames, 3))
    if root in matched:
        source_height = motion.rest_heads[matched[root]][2]
        scale = joints[root][2] / source_height if source_height > 1e-6 else 1.0
        translations = (motion.root_positions - motion.rest_heads[matched[root]]) * scale
    return local, translations


def _inherited_alignment(joint, parents, alignment):
    parent = parents[joint]
    while parent >= 0 and parent not in alignment:
        parent = parents[parent]
    return alignment.get(parent, np.eye(3))
