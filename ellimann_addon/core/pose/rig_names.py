"""The rigs people bring, by their own bone names: one name map per rig ({their bone: SMPL joint}), as data.

Names are compared without case and without a namespace prefix (Mixamo's ``mixamorig:``, ``mixamorig1:``, a
scene's ``Armature|``). A joint two of a map's names could fill takes the first the clip has, in the map's
order (SMPL-X has no ``left_hand``: its ``left_middle1`` stands in). A bone no map lists is not placed; a joint no
bone fills follows its parent (``core.pose.retarget``). Rigs nobody listed are placed by their names and their
hierarchy (``core.pose.bone_match``).
"""


def _sided(central, sided):
    """A name map from central entries and per-side templates ('{Side}': Left/Right, '{S}': L/R, '{s}': l/r,
    '{side}': left/right) of the joints' left/right names (their SMPL joint without its side)."""
    out = dict(central)
    for side, s in (("Left", "L"), ("Right", "R")):
        for theirs, joint in sided.items():
            out[theirs.format(Side=side, side=side.lower(), S=s, s=s.lower())] = f"{s}_{joint}"
    return out


# The limbs as Mixamo, LAFAN1 and the CMU database's BVH conversions name them (LeftUpLeg, RightForeArm, ...).
_MOTION_CAPTURE_LIMBS = {
    "{Side}UpLeg": "Hip",
    "{Side}Leg": "Knee",
    "{Side}Foot": "Ankle",
    "{Side}Shoulder": "Collar",
    "{Side}Arm": "Shoulder",
    "{Side}ForeArm": "Elbow",
    "{Side}Hand": "Wrist",
}
_MOTION_CAPTURE_SPINE = {"Hips": "Pelvis", "Spine": "Spine1", "Spine1": "Spine2", "Spine2": "Spine3"}
_UNREAL_LIMBS = {
    "thigh_{s}": "Hip",
    "calf_{s}": "Knee",
    "foot_{s}": "Ankle",
    "ball_{s}": "Foot",
    "clavicle_{s}": "Collar",
    "upperarm_{s}": "Shoulder",
    "lowerarm_{s}": "Elbow",
    "hand_{s}": "Wrist",
    "middle_01_{s}": "Hand",
}
_SMPL_JOINTS = ("Hip", "Knee", "Ankle", "Foot", "Collar", "Shoulder", "Elbow", "Wrist", "Hand")

RIG_NAME_MAPS = {
    # Biovision's own BVH example and the clips written after it (Hips, Chest, LeftCollar, LeftUpArm, ...).
    "biovision": _sided(
        {"Hips": "Pelvis", "Chest": "Spine1", "Neck": "Neck", "Head": "Head"},
        {
            "{Side}UpLeg": "Hip",
            "{Side}LowLeg": "Knee",
            "{Side}Foot": "Ankle",
            "{Side}Collar": "Collar",
            "{Side}UpArm": "Shoulder",
            "{Side}LowArm": "Elbow",
            "{Side}Hand": "Wrist",
        },
    ),
    # The CMU database's BVH conversions (Hips, LHipJoint, LeftUpLeg, LeftLeg, ..., LowerBack, Spine, Spine1, Neck,
    # Neck1, Head).
    "cmu": _sided(
        {
            "Hips": "Pelvis",
            "LowerBack": "Spine1",
            "Spine": "Spine2",
            "Spine1": "Spine3",
            "Neck": "Neck",
            "Head": "Head",
        },
        {**_MOTION_CAPTURE_LIMBS, "{Side}ToeBase": "Foot", "{Side}FingerBase": "Hand"},
    ),
    # Mixamo, with or without its "mixamorig:" prefix.
    "mixamo": _sided(
        {**_MOTION_CAPTURE_SPINE, "Neck": "Neck", "Head": "Head"},
        {**_MOTION_CAPTURE_LIMBS, "{Side}ToeBase": "Foot", "{Side}HandMiddle1": "Hand"},
    ),
    # Ubisoft's LAFAN1: Mixamo's names without fingers, LeftToe for the toes.
    "lafan1": _sided(
        {**_MOTION_CAPTURE_SPINE, "Neck": "Neck", "Head": "Head"}, {**_MOTION_CAPTURE_LIMBS, "{Side}Toe": "Foot"}
    ),
    # MakeHuman's and MPFB's default skeleton (the reference bodies' own: core.mannequin.skeleton.MAKEHUMAN_JOINTS).
    "makehuman": _sided(
        {
            "root": "Pelvis",
            "spine03": "Spine1",
            "spine02": "Spine2",
            "spine01": "Spine3",
            "neck01": "Neck",
            "head": "Head",
        },
        {
            "upperleg01.{S}": "Hip",
            "lowerleg01.{S}": "Knee",
            "foot.{S}": "Ankle",
            "toe3-1.{S}": "Foot",
            "clavicle.{S}": "Collar",
            "upperarm01.{S}": "Shoulder",
            "lowerarm01.{S}": "Elbow",
            "wrist.{S}": "Wrist",
            "finger3-1.{S}": "Hand",
        },
    ),
    # SMPL and SMPL-X: the joint names of their Python packages (pelvis, left_hip, ...), the short ones ElliMann
    # uses (L_Hip), and those of SMPL's FBX files (m_avg_L_Hip, f_avg_L_Hip).
    "smpl": {
        **{
            f"{prefix}{name}": joint
            for prefix in ("", "m_avg_", "f_avg_")
            for name, joint in (
                ("Pelvis", "Pelvis"),
                ("Spine1", "Spine1"),
                ("Spine2", "Spine2"),
                ("Spine3", "Spine3"),
                ("Neck", "Neck"),
                ("Head", "Head"),
                *((f"{s}_{j}", f"{s}_{j}") for s in "LR" for j in _SMPL_JOINTS),
            )
        },
        **_sided({}, {f"{{side}}_{j.lower()}": j for j in _SMPL_JOINTS}),
        **_sided({}, {"{side}_middle1": "Hand"}),
    },
    # Unreal's mannequins: UE5's Manny and Quinn (five spine bones, the clavicles on spine_05), UE4's (three).
    "unreal5": _sided(
        {"pelvis": "Pelvis", "spine_01": "Spine1", "spine_03": "Spine2", "spine_05": "Spine3"}
        | {"neck_01": "Neck", "head": "Head"},
        _UNREAL_LIMBS,
    ),
    "unreal": _sided(
        {"pelvis": "Pelvis", "spine_01": "Spine1", "spine_02": "Spine2", "spine_03": "Spine3"}
        | {"neck_01": "Neck", "head": "Head"},
        _UNREAL_LIMBS,
    ),
    # Rokoko Studio's actor (Hips, LeftThigh, LeftShin, ..., Spine1 to Spine4: the clavicles hang on Spine4).
    "rokoko": _sided(
        {"Hips": "Pelvis", "Spine1": "Spine1", "Spine2": "Spine2", "Spine4": "Spine3", "Neck": "Neck", "Head": "Head"},
        {
            "{Side}Thigh": "Hip",
            "{Side}Shin": "Knee",
            "{Side}Foot": "Ankle",
            "{Side}Toe": "Foot",
            "{Side}Shoulder": "Collar",
            "{Side}Arm": "Shoulder",
            "{Side}ForeArm": "Elbow",
            "{Side}Hand": "Wrist",
            "{Side}MiddleFinger1": "Hand",
        },
    ),
}
RIG_LABELS = {
    "biovision": "Biovision",
    "cmu": "CMU",
    "mixamo": "Mixamo",
    "lafan1": "LAFAN1",
    "makehuman": "MakeHuman/MPFB",
    "smpl": "SMPL/SMPL-X",
    "unreal5": "Unreal mannequin (UE5)",
    "unreal": "Unreal mannequin (UE4)",
    "rokoko": "Rokoko",
}
_FOLDED = {rig: {name.lower(): joint for name, joint in names.items()} for rig, names in RIG_NAME_MAPS.items()}
_ORDER = {rig: {name.lower(): i for i, name in enumerate(names)} for rig, names in RIG_NAME_MAPS.items()}


def bare_name(bone):
    """A bone's name without a namespace prefix ('mixamorig:Hips', 'Armature|Hips' -> 'Hips')."""
    return bone.rpartition(":")[2].rpartition("|")[2].strip()


def joint_of_bone(rig, bone):
    """The SMPL joint a rig's bone drives, or None: ``rig`` a key of RIG_NAME_MAPS; case and a namespace prefix
    are ignored."""
    return _FOLDED[rig].get(bare_name(bone).lower())


def listed_sources(rig, bones):
    """{SMPL joint name: index of the clip bone that drives it} of ``rig``'s map on the clip's ``bones``; a joint
    two names could fill takes the one earlier in the map."""
    ranked = {}
    for index, bone in enumerate(bones):
        key = bare_name(bone).lower()
        joint = _FOLDED[rig].get(key)
        if joint is not None:
            rank = _ORDER[rig][key]
            if joint not in ranked or rank < ranked[joint][0]:
                ranked[joint] = (rank, index)
    return {joint: index for joint, (_, index) in ranked.items()}
