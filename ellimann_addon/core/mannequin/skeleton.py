"""The skeleton of a mannequin: SMPL's 24 joints, which bone each part rides on, the anatomical limits, and the
mannequin JSON's ``joints`` section (other rigs' bone names: ``core.pose.rig_names``).

Joint names and order are SMPL's (``JOINT_NAMES``, ``PARENTS``: Pelvis is the root). ``L_`` is the body's left,
which is +X here. A joint's *bone* is the segment it rotates: the pieces on bone ``L_Elbow`` are the forearm's.
Rotations are expressed in world-aligned axes at rest (SMPL's convention): X lateral (+ to the body's left),
Y back (the body faces -Y), Z up.

Limits (``limits(joints)``) are ranges of the three intrinsic Euler angles (R = Rx(a) Ry(b) Rz(c)) of a joint's
local rotation seen in its *joint frame* (``joint_frames(joints)``): the world axes, except at the elbows,
whose x is the elbow's hinge axis taken from the mannequin's own upper arm and forearm. Hinges (elbows, knees,
toes) keep y and z at 0. Ranges are relative to the rest pose (the traced A-pose, upper arms 35 degrees from
vertical); the hinges' anatomical flexion ranges (knee 0-160, elbow 0-150) are shifted by the flexion the
rest pose already has, measured on the mannequin's joints. Degrees, from the open humanoid models of MuJoCo
and DeepMind Control's CMU humanoid. Right-side ranges mirror the left's: a mirror across x = 0 keeps a and
turns b, c into -b, -c.
"""

import numpy as np

from ..errors import Problem

JOINT_NAMES = (
    "Pelvis",
    "L_Hip",
    "R_Hip",
    "Spine1",
    "L_Knee",
    "R_Knee",
    "Spine2",
    "L_Ankle",
    "R_Ankle",
    "Spine3",
    "L_Foot",
    "R_Foot",
    "Neck",
    "L_Collar",
    "R_Collar",
    "Head",
    "L_Shoulder",
    "R_Shoulder",
    "L_Elbow",
    "R_Elbow",
    "L_Wrist",
    "R_Wrist",
    "L_Hand",
    "R_Hand",
)
PARENTS = (-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19, 20, 21)
JOINT_INDEX = {name: i for i, name in enumerate(JOINT_NAMES)}
JOINT_COUNT = len(JOINT_NAMES)
ROOT = 0


def joint_side(name):
    """'L', 'R' or 'C' (central) of a joint name."""
    return name[0] if name[:2] in ("L_", "R_") else "C"


def twin_joint(name):
    """'L_Knee' <-> 'R_Knee'; central joints are their own twin."""
    side = joint_side(name)
    return {"L": "R", "R": "L"}[side] + name[1:] if side != "C" else name


JOINT_TWINS = np.array([JOINT_INDEX[twin_joint(n)] for n in JOINT_NAMES])
CHILDREN = tuple(tuple(j for j, p in enumerate(PARENTS) if p == i) for i in range(JOINT_COUNT))

# Where each SMPL joint is on MakeHuman's default skeleton (skeleton.json of the reference bodies): the mean of
# these bones' heads. The spine's five bones give SMPL's three spine joints; the hand and the foot joints sit at
# the knuckles and at the toes' roots.
MAKEHUMAN_JOINTS = {
    "Pelvis": ("root",),
    "Spine1": ("spine03",),
    "Spine2": ("spine02",),
    "Spine3": ("spine01",),
    "Neck": ("neck01",),
    "Head": ("head",),
    **{
        f"{s}_{joint}": tuple(f"{bone}.{s}" for bone in bones)
        for s in "LR"
        for joint, bones in (
            ("Hip", ("upperleg01",)),
            ("Knee", ("lowerleg01",)),
            ("Ankle", ("foot",)),
            ("Foot", ("toe1-1", "toe2-1", "toe3-1", "toe4-1", "toe5-1")),
            ("Collar", ("clavicle",)),
            ("Shoulder", ("upperarm01",)),
            ("Elbow", ("lowerarm01",)),
            ("Wrist", ("wrist",)),
            ("Hand", ("finger2-1", "finger3-1", "finger4-1", "finger5-1")),
        )
    },
}


# The bone each part of a topology rides on, by the part's label (its name without number and side); a sided
# joint takes the part's side. Cushion pairs whose two parts are on different bones (Upper Arm/Forearm,
# Hand/Fingers, Foot/Toes, Oblique/Hip) cross a joint: core.pose.posed_pieces splits them there.
PART_BONES = {
    "Cranium": "Head",
    "Face": "Head",
    "Neck": "Neck",
    "Trapezius": "Collar",
    "Deltoid": "Shoulder",
    "Upper Arm": "Shoulder",
    "Forearm": "Elbow",
    "Hand": "Wrist",
    "Fingers": "Hand",
    "Breast": "Spine2",
    "Thorax": "Spine2",
    "Upper Back": "Spine2",
    "Oblique": "Spine1",
    "Rectus Abdominalis": "Spine1",
    "Lower Back": "Spine1",
    "Hip": "Pelvis",
    "Pelvis": "Pelvis",
    "Gluteus": "Pelvis",
    "Thigh": "Hip",
    "Knee": "Hip",
    "Calf": "Knee",
    "Ankle": "Knee",
    "Foot": "Ankle",
    "Toes": "Foot",
    # the fine topology's (tools/shipped/reference_topology_fine.py)
    "Occiput": "Head",
    "Forehead": "Head",
    "Jaw": "Head",
    "Base of Neck": "Neck",
    "Upper Chest": "Spine3",
    "Scapula": "Spine3",
    "Armpit": "Spine2",
    "Upper Breast": "Spine2",
    "Sternum": "Spine2",
    "Lower Ribs": "Spine2",
    "Lower Belly": "Pelvis",
    "Lumbar": "Pelvis",
    "Flank": "Pelvis",
    "Sacrum": "Pelvis",
    "Elbow": "Elbow",
    "Groin": "Hip",
    "Inner Thigh": "Hip",
    "Outer Thigh": "Hip",
    "Front Thigh": "Hip",
    "Buttock Fold": "Hip",
    "Back of Knee": "Hip",
    "Upper Shin": "Knee",
    "Heel": "Ankle",
    "Instep": "Ankle",
    "Under Breast": "Spine2",
    "Outer Hip": "Pelvis",
    "Upper Gluteus": "Pelvis",
    "Side Ribs": "Spine2",
    "Shoulder Top": "Collar",
    "Kneecap": "Hip",
}
# The part whose centre a joint follows in synthesis (the same IDW weights and proportional scales) and in the
# exact mode's deformation (core.mannequin.joints).
JOINT_ANCHORS = {
    "Pelvis": "14.a Pelvis",
    "Spine1": "13.b Lower Back",
    "Spine2": "11.b Upper Back",
    "Spine3": "11.b Upper Back",
    "Neck": "2.a Neck",
    "Head": "1.a Cranium",
    **{
        f"{s}_{joint}": f"{part}.{s}"
        for s in "LR"
        for joint, part in (
            ("Hip", "5.a Thigh"),
            ("Knee", "5.b Knee"),
            ("Ankle", "6.b Ankle"),
            ("Foot", "7.b Toes"),
            ("Collar", "10.a Trapezius"),
            ("Shoulder", "3.a Upper Arm"),
            ("Elbow", "3.b Forearm"),
            ("Wrist", "3.b Forearm"),
            ("Hand", "4.b Fingers"),
        )
    },
}


def part_label(name):
    """'3.a Upper Arm.L' -> 'Upper Arm'."""
    label = name.split(" ", 1)[1] if " " in name else name
    return label[:-2] if label.endswith((".L", ".R")) else label


def bone_name(part):
    """The SMPL joint whose bone a topology part (``Part``) rides on, or None if its label has none."""
    joint = PART_BONES.get(part_label(part.name))
    if joint is None:
        return None
    if joint in JOINT_INDEX:
        return joint
    return f"{part.side}_{joint}" if part.side in ("L", "R") else None


def bone_problems(topology):
    """Parts without a bone (a label PART_BONES does not know, or a sided bone on a central part)."""
    return [
        Problem(
            part.name,
            "bone",
            f"has no bone: its label '{part_label(part.name)}' is not one of "
            f"core.mannequin.skeleton.PART_BONES ({', '.join(sorted(PART_BONES))})",
        )
        for part in topology
        if bone_name(part) is None
    ]


def part_bones(topology):
    """(n,) int: the joint index of each part's bone. Raises MannequinError if a part has none."""
    from ..errors import MannequinError

    problems = bone_problems(topology)
    if problems:
        raise MannequinError(problems)
    return np.array([JOINT_INDEX[bone_name(part)] for part in topology], dtype=int)


def bone_names(topology):
    """{part name: SMPL joint name of its bone} (MannequinError if a part has none)."""
    return {name: JOINT_NAMES[b] for name, b in zip(topology.names, part_bones(topology))}


def cross_joint_pairs(topology):
    """The cushion pairs (first, second, joint) whose parts ride on different bones; ``joint`` is the index of
    the joint between them (the child bone's), or -1 if neither bone is the other's parent."""
    bones = part_bones(topology)
    out = []
    for i, j in topology.cushion_pairs:
        a, b = bones[i], bones[j]
        if a != b:
            out.append((i, j, b if _is_ancestor(a, b) else a if _is_ancestor(b, a) else -1))
    return out


def _is_ancestor(a, b):
    while b >= 0:
        b = PARENTS[b]
        if b == a:
            return True
    return False


# The limbs: root joint -> (the joint its direction points to, the joints below the root). Normalized synthesis
# (core.synthesis.idw, "height" and "proportional") scales a limb about its root in the limb's own axes, so that
# the arms keep the A-pose's angle (55 degrees below horizontal on every reference body) on a tall, narrow body.
LIMBS = {"Shoulder": ("Wrist", ("Elbow", "Wrist", "Hand")), "Hip": ("Ankle", ("Knee", "Ankle", "Foot"))}


def limb_roots(bones):
    """(len(bones),) int: for each joint index in ``bones``, the root joint of the sided limb its bone is on
    (the root's own bone included: the upper arm's pieces hang from the shoulder), else -1."""
    roots = {}
    for root, (_, below) in LIMBS.items():
        for side in "LR":
            for joint in (root, *below):
                roots[JOINT_INDEX[f"{side}_{joint}"]] = JOINT_INDEX[f"{side}_{root}"]
    return np.array([roots.get(int(b), -1) for b in bones], dtype=int)


def joint_limb_roots():
    """(24,) int: the root joint of the limb each joint lies below (the elbow's: the shoulder), -1 for the roots
    themselves and the joints of no limb."""
    roots = limb_roots(range(JOINT_COUNT))
    return np.where(roots == np.arange(JOINT_COUNT), -1, roots)


def limb_directions(joints):
    """{root joint index: (3,) unit direction of its limb (root to the end joint of LIMBS), the mean over the
    mannequins} for ``joints`` (k, 24, 3)."""
    out = {}
    for root, (end, _) in LIMBS.items():
        for side in "LR":
            r, e = JOINT_INDEX[f"{side}_{root}"], JOINT_INDEX[f"{side}_{end}"]
            out[r] = _unit(np.mean([_unit(j[e] - j[r]) for j in joints], axis=0))
    return out


# ------------------------------------------------------------------------------------------------ limits

# Euler ranges (degrees) of the left-side and central joints about the joint frame's x, y, z (relative to
# rest). Signs, left side: hip flexion (thigh forward) is -x, abduction (leg out to +X) -y; knee flexion +x;
# ankle dorsiflexion -x; spine and neck flexion (bending forward) +x; shoulder flexion (arm forward) -x,
# abduction (arm up, out to +X) -y; elbow flexion +x about its hinge.
_DEGREE_LIMITS = {
    "Pelvis": ((-180, 180), (-180, 180), (-180, 180)),  # the root: free
    "L_Hip": ((-140, 20), (-45, 30), (-45, 45)),
    "L_Knee": ((0, 160), (0, 0), (0, 0)),
    "L_Ankle": ((-25, 50), (-25, 25), (-25, 25)),
    "L_Foot": ((-60, 40), (0, 0), (0, 0)),
    "Spine1": ((-15, 30), (-20, 20), (-20, 20)),
    "Spine2": ((-15, 30), (-20, 20), (-20, 20)),
    "Spine3": ((-15, 30), (-20, 20), (-20, 20)),
    "Neck": ((-40, 45), (-35, 35), (-45, 45)),
    "Head": ((-30, 30), (-20, 20), (-35, 35)),
    "L_Collar": ((-15, 15), (-30, 10), (-25, 25)),
    "L_Shoulder": ((-150, 50), (-135, 40), (-80, 80)),
    "L_Elbow": ((0, 150), (0, 0), (0, 0)),
    "L_Wrist": ((-70, 70), (-30, 30), (-80, 80)),
    "L_Hand": ((-90, 90), (-30, 30), (-30, 30)),
}
HINGES = tuple(
    n for n in JOINT_NAMES if _DEGREE_LIMITS.get(n, _DEGREE_LIMITS.get(twin_joint(n)))[1:] == ((0, 0), (0, 0))
)


def _base_limits():
    out = np.zeros((JOINT_COUNT, 3, 2))
    for name in JOINT_NAMES:
        left = name if name in _DEGREE_LIMITS else twin_joint(name)
        ranges = np.radians(np.array(_DEGREE_LIMITS[left], dtype=float))
        if name != left:  # mirrored: a stays, b and c change sign (so do their ranges, swapped)
            ranges[1:] = -ranges[1:, ::-1]
        out[JOINT_INDEX[name]] = ranges
    return out


BASE_LIMITS = _base_limits()  # (24, 3, 2) radians, before the rest flexion of the hinges


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def elbow_frame(shoulder, elbow, wrist):
    """The elbow's joint frame (3, 3), columns x (hinge axis: positive rotation flexes, moving the forearm to
    the front), y, z (along the upper arm), and the rest flexion (radians) between upper arm and forearm."""
    upper, fore = _unit(elbow - shoulder), _unit(wrist - elbow)
    axis = np.cross(upper, fore)
    if np.linalg.norm(axis) < 1e-9:  # a straight arm: the hinge across it, flexing to the front (-Y)
        axis = np.cross(upper, [0.0, -1.0, 0.0])
    axis = _unit(axis)
    if np.dot(np.cross(axis, upper), [0.0, -1.0, 0.0]) < 0.0:  # flexion must bring the forearm forward
        axis = -axis
    flexion = float(np.arctan2(np.dot(np.cross(upper, fore), axis), np.dot(upper, fore)))
    z = upper
    y = np.cross(z, axis)
    return np.column_stack([axis, y, z]), flexion


def knee_flexion(hip, knee, ankle):
    """Rest flexion (radians) of a knee about world X: the shin's sagittal angle behind the thigh's."""
    thigh, shin = knee - hip, ankle - knee
    return float(np.arctan2(shin[1], -shin[2]) - np.arctan2(thigh[1], -thigh[2]))


def joint_frames(joints):
    """(24, 3, 3): each joint's frame for its limits (columns: its x, y, z axes in world coordinates)."""
    joints = np.asarray(joints, dtype=float)
    frames = np.repeat(np.eye(3)[None], JOINT_COUNT, axis=0)
    for s in "LR":
        frame, _ = elbow_frame(*(joints[JOINT_INDEX[f"{s}_{n}"]] for n in ("Shoulder", "Elbow", "Wrist")))
        frames[JOINT_INDEX[f"{s}_Elbow"]] = frame
    return frames


def rest_flexion(joints):
    """{joint index: rest flexion (radians)} of the knees and elbows on these joints."""
    joints = np.asarray(joints, dtype=float)
    out = {}
    for s in "LR":
        idx = {n: JOINT_INDEX[f"{s}_{n}"] for n in ("Hip", "Knee", "Ankle", "Shoulder", "Elbow", "Wrist")}
        out[idx["Knee"]] = knee_flexion(joints[idx["Hip"]], joints[idx["Knee"]], joints[idx["Ankle"]])
        out[idx["Elbow"]] = elbow_frame(joints[idx["Shoulder"]], joints[idx["Elbow"]], joints[idx["Wrist"]])[1]
    return out


def limits(joints):
    """(24, 3, 2) radians: the Euler ranges of every joint of a mannequin with these rest joints."""
    out = BASE_LIMITS.copy()
    for index, flexion in rest_flexion(joints).items():
        out[index, 0] -= flexion
    return out
