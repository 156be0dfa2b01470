"""Test clips in the conventions people bring (written from scratch on a mannequin's own joints, no downloaded
files): each rig's bone names, its hierarchy with the bones a mannequin lacks (CMU's LHipJoint and Neck1, twist
bones, fingers, Unreal's root, MakeHuman's five spine bones), its rest pose (T-pose, A-pose or arms down), its
units and rotation orders, and a motion: every joint moving smoothly within the anatomical ranges, the knee
and elbow bending about their hinges, helper bones twisting, and one frame where the left knee bends backwards
and the right elbow over-straightens (beyond their limits, to be clamped).
"""

import numpy as np

from devkit.bvh import Clip, axis_rotation, mirrored, rotation_x, write_bvh
from ellimann_addon.core.mannequin.skeleton import JOINT_INDEX, JOINT_NAMES, PARENTS
from ellimann_addon.core.pose.kinematics import forward_kinematics
from ellimann_addon.core.pose.standard import attention, t_pose

CM, INCH, M = 0.01, 0.0254, 1.0
CMU_UNIT = 0.0254 / 0.45
LIMBS = (
    ("Hip", "Knee", "Ankle", "Foot"),
    ("Collar", "Shoulder", "Elbow", "Wrist", "Hand"),
)


def _sided(bones):
    """Expand bones whose names hold '{s}' style templates into both sides; each entry (name template, parent
    template, role (an SMPL joint or None for a helper), where (a joint, or (joint, joint, t) between two))."""
    out = []
    for name, parent, role, where in bones:
        if "{" not in name:
            out.append((name, parent, role, where))
            continue
        for side, s in (("Left", "L"), ("Right", "R")):
            fill = dict(Side=side, side=side.lower(), S=s, s=s.lower())
            place = tuple(_side_of(w, s) for w in where) if isinstance(where, tuple) else _side_of(where, s)
            out.append((name.format(**fill), parent.format(**fill) if parent else parent, _side_of(role, s), place))
    return out


def _side_of(value, s):
    """'?Hip' -> 'L_Hip' on side ``s``; anything else as it is."""
    return f"{s}_{value[1:]}" if isinstance(value, str) and value.startswith("?") else value


def _mocap(toe="{Side}ToeBase", spine=("Spine", "Spine1", "Spine2"), fingers=True, hip_joint=False):
    """Mixamo / LAFAN1 / CMU-like bones."""
    bones = [("Hips", None, "Pelvis", "Pelvis")]
    parent = "Hips"
    if hip_joint:  # CMU: LowerBack starts at the hips
        bones.append(("{Side}HipJoint".replace("{Side}", "{S}"), "Hips", None, "Pelvis"))
    for name, role in zip(spine, ("Spine1", "Spine2", "Spine3")):
        where = "Pelvis" if hip_joint and role == "Spine1" else role
        bones.append((name, parent, role, where))
        parent = name
    leg_parent = "{S}HipJoint" if hip_joint else "Hips"
    bones += [
        ("Neck", spine[-1], "Neck", "Neck"),
        *([("Neck1", "Neck", None, ("Neck", "Head", 0.5))] if hip_joint else []),
        ("Head", "Neck1" if hip_joint else "Neck", "Head", "Head"),
        ("{Side}UpLeg", leg_parent, "?Hip", "?Hip"),
        ("{Side}Leg", "{Side}UpLeg", "?Knee", "?Knee"),
        ("{Side}Foot", "{Side}Leg", "?Ankle", "?Ankle"),
        (toe, "{Side}Foot", "?Foot", "?Foot"),
        ("{Side}Shoulder", spine[-1], "?Collar", "?Collar"),
        ("{Side}Arm", "{Side}Shoulder", "?Shoulder", "?Shoulder"),
        ("{Side}ForeArm", "{Side}Arm", "?Elbow", "?Elbow"),
        ("{Side}Hand", "{Side}ForeArm", "?Wrist", "?Wrist"),
    ]
    if fingers:
        bones += [
            ("{Side}HandMiddle1" if not hip_joint else "{Side}FingerBase", "{Side}Hand", "?Hand", "?Hand"),
            ("{Side}HandThumb1" if not hip_joint else "{S}Thumb", "{Side}Hand", None, ("?Wrist", "?Hand", 0.6)),
        ]
    return bones


def _smpl_name(joint):
    """SMPL's Python names: pelvis, left_hip, spine1, ..."""
    if joint[1] == "_":
        return f"{'left' if joint[0] == 'L' else 'right'}_{joint[2:].lower()}"
    return joint.lower()


def _smpl_parent(joint):
    parent = PARENTS[JOINT_INDEX[joint]]
    return _smpl_name(JOINT_NAMES[parent]) if parent >= 0 else None


RIGS = {
    "biovision": dict(
        unit=INCH,
        rest="down",
        bones=[
            ("Hips", None, "Pelvis", "Pelvis"),
            ("Chest", "Hips", "Spine1", "Spine1"),
            ("Neck", "Chest", "Neck", "Neck"),
            ("Head", "Neck", "Head", "Head"),
            ("{Side}Collar", "Chest", "?Collar", "?Collar"),
            ("{Side}UpArm", "{Side}Collar", "?Shoulder", "?Shoulder"),
            ("{Side}LowArm", "{Side}UpArm", "?Elbow", "?Elbow"),
            ("{Side}Hand", "{Side}LowArm", "?Wrist", "?Wrist"),
            ("{Side}UpLeg", "Hips", "?Hip", "?Hip"),
            ("{Side}LowLeg", "{Side}UpLeg", "?Knee", "?Knee"),
            ("{Side}Foot", "{Side}LowLeg", "?Ankle", "?Ankle"),
        ],
    ),
    "cmu": dict(
        unit=CMU_UNIT, order="ZYX", rest="t", bones=_mocap(hip_joint=True, spine=("LowerBack", "Spine", "Spine1"))
    ),
    "mixamo": dict(unit=CM, rest="t", bones=_mocap(), prefix="mixamorig:"),
    "mixamo_bare": dict(unit=CM, rest="t", bones=_mocap(), order="XYZ"),
    "lafan1": dict(unit=CM, order="ZYX", rest="t", bones=_mocap(toe="{Side}Toe", fingers=False)),
    "makehuman": dict(
        unit=CM,
        order="XYZ",
        rest="a",
        bones=[
            ("root", None, "Pelvis", "Pelvis"),
            ("spine05", "root", None, ("Pelvis", "Spine1", 1 / 3)),
            ("spine04", "spine05", None, ("Pelvis", "Spine1", 2 / 3)),
            ("spine03", "spine04", "Spine1", "Spine1"),
            ("spine02", "spine03", "Spine2", "Spine2"),
            ("spine01", "spine02", "Spine3", "Spine3"),
            ("neck01", "spine01", "Neck", "Neck"),
            ("neck02", "neck01", None, ("Neck", "Head", 0.5)),
            ("head", "neck02", "Head", "Head"),
            ("pelvis.{S}", "root", None, ("Pelvis", "?Hip", 0.5)),
            ("upperleg01.{S}", "pelvis.{S}", "?Hip", "?Hip"),
            ("upperleg02.{S}", "upperleg01.{S}", "twist", ("?Hip", "?Knee", 0.5)),
            ("lowerleg01.{S}", "upperleg02.{S}", "?Knee", "?Knee"),
            ("lowerleg02.{S}", "lowerleg01.{S}", "twist", ("?Knee", "?Ankle", 0.5)),
            ("foot.{S}", "lowerleg02.{S}", "?Ankle", "?Ankle"),
            ("toe3-1.{S}", "foot.{S}", "?Foot", "?Foot"),
            ("clavicle.{S}", "spine01", "?Collar", "?Collar"),
            ("shoulder01.{S}", "clavicle.{S}", None, ("?Collar", "?Shoulder", 0.8)),
            ("upperarm01.{S}", "shoulder01.{S}", "?Shoulder", "?Shoulder"),
            ("upperarm02.{S}", "upperarm01.{S}", "twist", ("?Shoulder", "?Elbow", 0.5)),
            ("lowerarm01.{S}", "upperarm02.{S}", "?Elbow", "?Elbow"),
            ("lowerarm02.{S}", "lowerarm01.{S}", "twist", ("?Elbow", "?Wrist", 0.5)),
            ("wrist.{S}", "lowerarm02.{S}", "?Wrist", "?Wrist"),
            ("finger3-1.{S}", "wrist.{S}", "?Hand", "?Hand"),
        ],
    ),
    "smpl": dict(unit=M, order="XYZ", rest="t", bones=[(_smpl_name(n), _smpl_parent(n), n, n) for n in JOINT_NAMES]),
    "unreal": dict(
        unit=CM,
        rest="a",
        bones=[
            ("root", None, None, ("Pelvis", "floor")),
            ("pelvis", "root", "Pelvis", "Pelvis"),
            ("spine_01", "pelvis", "Spine1", "Spine1"),
            ("spine_02", "spine_01", "Spine2", "Spine2"),
            ("spine_03", "spine_02", "Spine3", "Spine3"),
            ("neck_01", "spine_03", "Neck", "Neck"),
            ("head", "neck_01", "Head", "Head"),
            ("thigh_{s}", "pelvis", "?Hip", "?Hip"),
            ("thigh_twist_01_{s}", "thigh_{s}", "twist", ("?Hip", "?Knee", 0.3)),
            ("calf_{s}", "thigh_{s}", "?Knee", "?Knee"),
            ("foot_{s}", "calf_{s}", "?Ankle", "?Ankle"),
            ("ball_{s}", "foot_{s}", "?Foot", "?Foot"),
            ("clavicle_{s}", "spine_03", "?Collar", "?Collar"),
            ("upperarm_{s}", "clavicle_{s}", "?Shoulder", "?Shoulder"),
            ("upperarm_twist_01_{s}", "upperarm_{s}", "twist", ("?Shoulder", "?Elbow", 0.3)),
            ("lowerarm_{s}", "upperarm_{s}", "?Elbow", "?Elbow"),
            ("hand_{s}", "lowerarm_{s}", "?Wrist", "?Wrist"),
            ("middle_01_{s}", "hand_{s}", "?Hand", "?Hand"),
        ],
    ),
    "rokoko": dict(
        unit=CM,
        rest="t",
        bones=[
            ("Hips", None, "Pelvis", "Pelvis"),
            ("Spine1", "Hips", "Spine1", "Spine1"),
            ("Spine2", "Spine1", "Spine2", "Spine2"),
            ("Spine3", "Spine2", None, ("Spine2", "Spine3", 0.5)),
            ("Spine4", "Spine3", "Spine3", "Spine3"),
            ("Neck", "Spine4", "Neck", "Neck"),
            ("Head", "Neck", "Head", "Head"),
            ("{Side}Thigh", "Hips", "?Hip", "?Hip"),
            ("{Side}Shin", "{Side}Thigh", "?Knee", "?Knee"),
            ("{Side}Foot", "{Side}Shin", "?Ankle", "?Ankle"),
            ("{Side}Toe", "{Side}Foot", "?Foot", "?Foot"),
            ("{Side}Shoulder", "Spine4", "?Collar", "?Collar"),
            ("{Side}Arm", "{Side}Shoulder", "?Shoulder", "?Shoulder"),
            ("{Side}ForeArm", "{Side}Arm", "?Elbow", "?Elbow"),
            ("{Side}Hand", "{Side}ForeArm", "?Wrist", "?Wrist"),
        ],
    ),
    # Nobody listed this one (3ds Max Biped-like names, a unnamed knee bone): placed by names and hierarchy.
    "unlisted": dict(
        unit=M,
        order="YXZ",
        rest="a",
        bones=[
            ("Bip01", None, None, ("Pelvis", "floor")),
            ("Bip01_Pelvis", "Bip01", "Pelvis", "Pelvis"),
            ("Bip01_Spine", "Bip01_Pelvis", "Spine1", "Spine1"),
            ("Bip01_Spine1", "Bip01_Spine", "Spine2", "Spine2"),
            ("Bip01_Spine2", "Bip01_Spine1", "Spine3", "Spine3"),
            ("Bip01_Neck", "Bip01_Spine2", "Neck", "Neck"),
            ("Bip01_Head", "Bip01_Neck", "Head", "Head"),
            ("Bip01_{S}_Thigh", "Bip01_Pelvis", "?Hip", "?Hip"),
            ("Bip01_{S}_Bone02", "Bip01_{S}_Thigh", "?Knee", "?Knee"),
            ("Bip01_{S}_Foot", "Bip01_{S}_Bone02", "?Ankle", "?Ankle"),
            ("Bip01_{S}_Toe0", "Bip01_{S}_Foot", "?Foot", "?Foot"),
            ("Bip01_{S}_Clavicle", "Bip01_Spine2", "?Collar", "?Collar"),
            ("Bip01_{S}_UpperArm", "Bip01_{S}_Clavicle", "?Shoulder", "?Shoulder"),
            ("Bip01_{S}_Forearm", "Bip01_{S}_UpperArm", "?Elbow", "?Elbow"),
            ("Bip01_{S}_Hand", "Bip01_{S}_Forearm", "?Wrist", "?Wrist"),
        ],
    ),
}
RIGS["unreal5"] = dict(
    RIGS["unreal"],
    bones=[
        ("root", None, None, ("Pelvis", "floor")),
        ("pelvis", "root", "Pelvis", "Pelvis"),
        ("spine_01", "pelvis", "Spine1", "Spine1"),
        ("spine_02", "spine_01", None, ("Spine1", "Spine2", 0.5)),
        ("spine_03", "spine_02", "Spine2", "Spine2"),
        ("spine_04", "spine_03", None, ("Spine2", "Spine3", 0.5)),
        ("spine_05", "spine_04", "Spine3", "Spine3"),
        ("neck_01", "spine_05", "Neck", "Neck"),
        ("neck_02", "neck_01", None, ("Neck", "Head", 0.5)),
        ("head", "neck_02", "Head", "Head"),
        *[b if b[1] != "spine_03" else (b[0], "spine_05", b[2], b[3]) for b in RIGS["unreal"]["bones"][7:]],
    ],
)
RIGS["smplx"] = dict(
    RIGS["smpl"],
    bones=[b for b in RIGS["smpl"]["bones"] if not b[0].endswith("_hand")]
    + [(f"{side}_middle1", f"{side}_wrist", f"{s}_Hand", f"{s}_Hand") for side, s in (("left", "L"), ("right", "R"))]
    + [("jaw", "head", None, ("Head", "Neck", 0.5))],
)
CONVENTIONS = tuple(RIGS)


# The rigs' own proportions against the mannequin's: each segment (a joint's offset from its parent) stretched.
STRETCH = {"Hip": 1.15, "Knee": 1.08, "Ankle": 1.05, "Collar": 1.2, "Shoulder": 1.1, "Elbow": 0.92, "Wrist": 1.06}
STRETCH.update({"Spine2": 1.1, "Spine3": 0.9, "Neck": 1.05, "Head": 1.1})


def _rest_joints(joints, rest, stretch=True):
    """The SMPL joints in the rig's rest pose ('a' the mannequin's own A-pose, 't' a T-pose, 'down' arms hanging)
    and, with ``stretch``, the rig's own proportions (STRETCH)."""
    joints = np.asarray(joints, float)
    if rest != "a":
        pose = t_pose(joints) if rest == "t" else attention(joints)
        joints = forward_kinematics(joints, pose.rotations)[2]
    if not stretch:
        return joints
    out = joints.copy()
    for j in range(1, len(joints)):  # parents first
        factor = STRETCH.get(JOINT_NAMES[j][2:] if JOINT_NAMES[j][1] == "_" else JOINT_NAMES[j], 1.0)
        out[j] = out[PARENTS[j]] + factor * (joints[j] - joints[PARENTS[j]])
    return out


def _position(where, joints):
    if isinstance(where, str):
        return joints[JOINT_INDEX[where]]
    if where[1] == "floor":
        return joints[JOINT_INDEX[where[0]]] * [1.0, 1.0, 0.0]
    first, second, t = where
    a, b = joints[JOINT_INDEX[first]], joints[JOINT_INDEX[second]]
    return a + t * (b - a)


def rig_skeleton(convention, joints, stretch=True):
    """(names, parents, rest heads (k, 3), roles, End Sites {bone: offset}) of ``convention`` on SMPL ``joints``
    (in the rig's own proportions with ``stretch``)."""
    spec = RIGS[convention]
    bones = _sided(spec["bones"])
    rest = _rest_joints(joints, spec["rest"], stretch)
    names = [spec.get("prefix", "") + b[0] for b in bones]
    index = {b[0]: i for i, b in enumerate(bones)}
    parents = [index[b[1]] if b[1] else -1 for b in bones]
    heads = np.array([_position(b[3], rest) for b in bones])
    roles = [b[2] for b in bones]
    ends = {}
    for i in range(len(bones)):
        if i in parents:
            continue
        parent = parents[i]
        direction = heads[i] - heads[parent] if parent >= 0 else np.array([0.0, 0.0, 0.1])
        ends[i] = 0.4 * direction
        if roles[i] in ("L_Foot", "R_Foot", "L_Ankle", "R_Ankle"):  # the toes' tips on the floor
            ends[i] = np.array([0.0, -0.06, -heads[i][2]])
        if roles[i] == "Head":
            ends[i] = np.array([0.0, 0.0, 0.12])
    return names, parents, heads, roles, ends


def twin_indices(names):
    """Each bone's mirror twin by its name (Left/Right, L/R, l/r swapped)."""
    swaps = (("Left", "Right"), ("left", "right"), (".L", ".R"), ("_l", "_r"), ("_L_", "_R_"), ("LHip", "RHip"))
    swaps += tuple((b, a) for a, b in swaps) + (("LThumb", "RThumb"), ("RThumb", "LThumb"))
    index = {n: i for i, n in enumerate(names)}
    out = []
    for name in names:
        twin = next((name.replace(a, b) for a, b in swaps if a in name and name.replace(a, b) in index), name)
        out.append(index[twin])
    return out


def _hinge_axis(direction):
    """The axis a limb bone pointing along ``direction`` bends forward about (a positive turn moves it to -Y)."""
    axis = np.cross(direction, [0.0, -1.0, 0.0])
    return axis / np.linalg.norm(axis)


def motion(roles, heads, parents, frames, seed=0):
    """(F, k, 3, 3) local rotations: a smooth motion within the ranges; at the middle frame the left knee bends
    backwards and the right elbow over-straightens."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2.0 * np.pi, frames, endpoint=False)
    out = np.broadcast_to(np.eye(3), (frames, len(roles), 3, 3)).copy()

    def wave(amplitude):
        return amplitude * np.sin(t * rng.integers(1, 3) + rng.uniform(0, 2 * np.pi))

    for i, role in enumerate(roles):
        kind = None if role in (None, "twist") else role[2:] if role[1] == "_" else role
        direction = heads[i] - heads[parents[i]] if parents[i] >= 0 else np.array([0.0, 0.0, 1.0])
        if role == "twist" or (role is None and parents[i] >= 0):  # helpers turn a little, twists about the bone
            axis = heads[[c for c, p in enumerate(parents) if p == i][0]] - heads[i] if i in parents else direction
            angles = [(axis if role == "twist" else [1.0, 0.0, 0.0], wave(8.0))]
        elif kind == "Knee":
            angles = [([1.0, 0.0, 0.0], 5.0 + 25.0 * (1.0 + np.sin(t + rng.uniform(0, 6)))), ([0, 0, 1.0], wave(4))]
        elif kind == "Elbow":  # bending about its hinge, and turning about the forearm as no hinge does
            forearm = heads[[c for c, p in enumerate(parents) if p == i][0]] - heads[i]
            angles = [(_hinge_axis(forearm), 15.0 + 25.0 * (1.0 + np.sin(t + rng.uniform(0, 6)))), (forearm, wave(10))]
        elif kind == "Hip":
            angles = [([1.0, 0.0, 0.0], -10.0 + wave(20.0)), ([0.0, 0.0, 1.0], wave(8.0)), ([0.0, 1.0, 0.0], wave(5))]
        elif kind == "Shoulder":
            angles = [([1.0, 0.0, 0.0], wave(25.0)), ([0.0, 1.0, 0.0], wave(8.0)), ([0.0, 0.0, 1.0], wave(10))]
        elif kind in ("Spine1", "Spine2", "Spine3"):
            angles = [([1.0, 0.0, 0.0], 5.0 + wave(6.0)), ([0.0, 1.0, 0.0], wave(5.0)), ([0.0, 0.0, 1.0], wave(6))]
        elif kind in ("Neck", "Head", "Wrist"):
            angles = [([1.0, 0.0, 0.0], wave(12.0)), ([0.0, 0.0, 1.0], wave(10.0))]
        elif kind in ("Ankle", "Foot", "Hand"):
            angles = [([1.0, 0.0, 0.0], wave(8.0))]
        elif kind in ("Collar", "Pelvis"):
            angles = [([0.0, 0.0, 1.0], wave(4.0)), ([1.0, 0.0, 0.0], wave(3.0))]
        else:
            angles = []
        for axis, degrees in angles:
            out[:, i] = np.stack(
                [a @ axis_rotation(axis, d) for a, d in zip(out[:, i], np.broadcast_to(degrees, t.shape))]
            )
    middle = frames // 2
    for role, rotation in (("L_Knee", rotation_x(-25.0)), ("R_Elbow", None)):
        if role in roles:
            i = roles.index(role)
            if rotation is None:
                forearm = heads[[c for c, p in enumerate(parents) if p == i][0]] - heads[i]
                rotation = axis_rotation(_hinge_axis(forearm), -40.0)
            out[middle, i] = rotation
    return out


def convention_clip(convention, joints, frames=24, seed=1, mirror=False, stretch=True):
    """The test clip of ``convention`` (a key of RIGS) on a mannequin's SMPL ``joints`` (in the rig's proportions
    with ``stretch``, else the mannequin's): a devkit.bvh.Clip walking forward half a metre, the hips bobbing;
    ``mirror``: its mirror image."""
    spec = RIGS[convention]
    names, parents, heads, roles, ends = rig_skeleton(convention, joints, stretch)
    rotations = motion(roles, heads, parents, frames, seed)
    t = np.arange(frames) / frames
    path = np.stack([0.02 * np.sin(2 * np.pi * t), -0.5 * t, 0.015 * np.sin(4 * np.pi * t)], axis=-1)
    roots = [i for i, p in enumerate(parents) if p < 0]
    positions = {roots[0]: heads[roots[0]] + path}
    if roles[roots[0]] is None:  # a static root at the floor: the pelvis moves
        pelvis = roles.index("Pelvis")
        positions = {
            roots[0]: np.broadcast_to(heads[roots[0]], (frames, 3)),
            pelvis: heads[pelvis] - heads[roots[0]] + path,
        }
    orders = {i: "ZXY" for i in positions} if spec.get("order", "ZXY") != "ZXY" else {}
    clip = Clip(
        names,
        parents,
        heads,
        rotations,
        positions,
        ends,
        orders,
        spec.get("order", "ZXY"),
        spec["unit"],
        1.0 / 30.0,
        twin_indices(names),
    )
    return mirrored(clip) if mirror else clip


def bytes_per_frame(convention, mannequin, folder, counts=(200, 600)):
    """(measured, estimated) bytes a frame takes to read a clip of ``convention``, retarget it onto ``mannequin``
    and write it as .json: the peaks tracemalloc sees at two lengths, and core.formats.bvh.bytes_needed's."""
    import tracemalloc
    from pathlib import Path

    from ellimann_addon.core.formats.bvh import bytes_needed, read_bvh
    from ellimann_addon.core.formats.table import write_file
    from ellimann_addon.core.pose.clip import clip_onto

    peaks, sizes = [], []
    for frames in counts:
        clip = convention_clip(convention, mannequin.joints, frames=frames)
        path = write_bvh(Path(folder) / "memory.bvh", clip)
        tracemalloc.start()
        read = read_bvh(path)
        write_file(mannequin, Path(folder) / "memory.json", frames=clip_onto(mannequin, read.motion, read.match).poses)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
        channels = 3 * len(clip.names) + 3 * len(clip.positions)
        sizes.append(bytes_needed(frames, channels, len(read.motion.names)))
    span = counts[1] - counts[0]
    return (peaks[1] - peaks[0]) / span, (sizes[1] - sizes[0]) / span
