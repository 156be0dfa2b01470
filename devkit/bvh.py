"""Small BVH clips for tests, written from scratch (no downloaded files).

A clip is a skeleton (bone names, parents, heads in ElliMann's axes, metres) and per frame each bone's
rotation relative to its parent in world axes at rest (the core's pose convention, also BVH's: a BVH
rests with every joint frame along the world axes) plus the root's position. The file is in BVH's
own axes (Y up, the character facing +Z, centimetres), rotations as ``Zrotation Xrotation Yrotation``
Euler angles in degrees, as CMU's and Mixamo's clips are.
"""

import numpy as np

# ElliMann (x, y, z) = TO_ELLIMANN @ BVH (x, y, z): BVH's +Z (the character's front) is ElliMann's -Y.
TO_ELLIMANN = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
CM_PER_M = 100.0

# Bone names per rig style, for the SMPL joints they stand for (CMU clips as MotionBuilder-style BVH;
# Mixamo with its "mixamorig:" prefix).
STYLES = {
    "cmu": {
        "Pelvis": "Hips",
        "L_Hip": "LeftUpLeg",
        "R_Hip": "RightUpLeg",
        "Spine1": "LowerBack",
        "L_Knee": "LeftLeg",
        "R_Knee": "RightLeg",
        "Spine2": "Spine",
        "L_Ankle": "LeftFoot",
        "R_Ankle": "RightFoot",
        "Spine3": "Spine1",
        "L_Foot": "LeftToeBase",
        "R_Foot": "RightToeBase",
        "Neck": "Neck",
        "L_Collar": "LeftShoulder",
        "R_Collar": "RightShoulder",
        "Head": "Head",
        "L_Shoulder": "LeftArm",
        "R_Shoulder": "RightArm",
        "L_Elbow": "LeftForeArm",
        "R_Elbow": "RightForeArm",
        "L_Wrist": "LeftHand",
        "R_Wrist": "RightHand",
        "L_Hand": "LeftFingerBase",
        "R_Hand": "RightFingerBase",
    },
}
STYLES["mixamo"] = {joint: "mixamorig:" + name for joint, name in STYLES["cmu"].items()}
STYLES["mixamo"].update(
    {
        "Spine1": "mixamorig:Spine",
        "Spine2": "mixamorig:Spine1",
        "Spine3": "mixamorig:Spine2",
        "L_Hand": "mixamorig:LeftHandMiddle1",
        "R_Hand": "mixamorig:RightHandMiddle1",
    }
)


def zxy_degrees(rotation):
    """Euler angles (z, x, y) in degrees with ``rotation = Rz(z) @ Rx(x) @ Ry(y)`` (BVH's ZXY channels)."""
    r = np.asarray(rotation, float)
    x = np.arcsin(np.clip(r[2, 1], -1.0, 1.0))
    y = np.arctan2(-r[2, 0], r[2, 2])
    z = np.arctan2(-r[0, 1], r[1, 1])
    return np.degrees([z, x, y])


def write_bvh(path, names, parents, heads, rotations, root_positions, frame_time=1.0 / 24.0):
    """Write a BVH clip: ``heads`` (k, 3) at rest, ``rotations`` (F, k, 3, 3) local, ``root_positions`` (F, 3),
    all in ElliMann's axes and metres. Returns the path."""
    heads = np.asarray(heads, float)
    to_bvh = TO_ELLIMANN.T
    children = {i: [j for j in range(len(names)) if parents[j] == i] for i in range(len(names))}
    lines = ["HIERARCHY"]

    def joint(i, depth):
        pad = "  " * depth
        offset = heads[i] - (heads[parents[i]] if parents[i] >= 0 else 0.0)
        lines.append(f"{pad}{'ROOT' if parents[i] < 0 else 'JOINT'} {names[i]}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}  OFFSET " + " ".join(f"{v:.6f}" for v in to_bvh @ offset * CM_PER_M))
        channels = "6 Xposition Yposition Zposition" if parents[i] < 0 else "3"
        lines.append(f"{pad}  CHANNELS {channels} Zrotation Xrotation Yrotation")
        for child in children[i]:
            joint(child, depth + 1)
        if not children[i]:
            end = [f"{pad}  End Site", f"{pad}  {{", f"{pad}    OFFSET 0.000000 5.000000 0.000000", f"{pad}  }}"]
            lines.extend(end)
        lines.append(f"{pad}}}")

    order = []

    def visit(i):
        order.append(i)
        for child in children[i]:
            visit(child)

    root = next(i for i in range(len(names)) if parents[i] < 0)
    joint(root, 0)
    visit(root)
    rotations = np.asarray(rotations, float)
    lines += ["MOTION", f"Frames: {len(rotations)}", f"Frame Time: {frame_time:.6f}"]
    for frame, position in zip(rotations, np.asarray(root_positions, float)):
        values = list(to_bvh @ position * CM_PER_M)
        for i in order:
            values += list(zxy_degrees(to_bvh @ frame[i] @ TO_ELLIMANN))
        lines.append(" ".join(f"{v:.6f}" for v in values))
    with open(path, "w", encoding="utf-8") as stream:
        stream.write("\n".join(lines) + "\n")
    return path


def rotation_x(degrees):
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rotation_y(degrees):
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def clip_for(joint_names, parents, joints, style, frames, bends=None, root_path=None, frame_time=1.0 / 24.0):
    """A clip on the mannequin's own skeleton (its rest = the mannequin's rest) with the bone names of
    ``style``: ``bends`` {(joint name, frame): local rotation (3, 3)}, the rest otherwise; the root at its
    rest head plus ``root_path`` (F, 3). Returns (names, parents, heads, rotations, root positions)."""
    names = [STYLES[style][j] if style in STYLES else j for j in joint_names]
    rotations = np.broadcast_to(np.eye(3), (frames, len(names), 3, 3)).copy()
    for (joint, frame), rotation in (bends or {}).items():
        rotations[frame, joint_names.index(joint)] = rotation
    root = next(i for i in range(len(names)) if parents[i] < 0)
    positions = np.asarray(joints, float)[root] + (np.zeros((frames, 3)) if root_path is None else root_path)
    return names, list(parents), np.asarray(joints, float), rotations, positions
