"""BVH clips read and retargeted with numpy alone (core.formats.bvh, core.pose.bone_match, retarget, clip): every
rig's names placed where they belong (and their mirror images mirrored), the clip's own directions kept, rest poses
that differ, clamps summarised per joint, the feet against the floor, units, resampling. The clips are written
here (devkit.clips), not downloaded; the comparison with Blender's own importer is
tests/blender/features/test_bvh.py."""

import numpy as np
import pytest

from devkit import bvh, clips
from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.formats.bvh import read_bvh
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.skeleton import JOINT_INDEX, JOINT_NAMES, PARENTS, joint_frames
from ellimann_addon.core.pose.bone_match import BY_NAMES, bone_part, match_bones, name_words
from ellimann_addon.core.pose.clip import clip_onto
from ellimann_addon.core.pose.kinematics import axis_angle, forward_kinematics, mirror_pose
from ellimann_addon.core.pose.rig_names import RIG_NAME_MAPS, joint_of_bone
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

EXPECTED_RIG = {"mixamo_bare": "mixamo", "smplx": "smpl", "unlisted": BY_NAMES}
# Each joint and the joint at the end of its segment: thighs, shins, upper arms, forearms, the spine.
SEGMENTS = (
    *((f"{s}_{a}", f"{s}_{b}") for s in "LR" for a, b in (("Hip", "Knee"), ("Knee", "Ankle"))),
    *((f"{s}_{a}", f"{s}_{b}") for s in "LR" for a, b in (("Shoulder", "Elbow"), ("Elbow", "Wrist"))),
    ("Spine1", None),
    ("Spine2", None),
    ("Spine3", None),
)


@pytest.fixture(scope="module")
def average():
    return Mannequin.load(REFERENCE_FOLDER / "average.json")


def written(tmp_path, convention, joints, mirror=False, **options):
    clip = clips.convention_clip(convention, joints, mirror=mirror, **options)
    return clip, bvh.write_bvh(tmp_path / f"{convention}{'_mirror' if mirror else ''}.bvh", clip)


def segment_directions(match, joints, posed_joints, clip_heads):
    """{segment: (mannequin directions (F, 3), the clip's (F, 3))} of the driven SEGMENTS."""
    out = {}
    for first, second in SEGMENTS:
        a = JOINT_INDEX[first]
        b = match.segment_end(a) if second is None else JOINT_INDEX[second]
        if a in match.sources and b is not None and b in match.sources and match.segment_end(a) == b:
            clip = clip_heads[:, match.sources[b]] - clip_heads[:, match.sources[a]]
            out[(first, JOINT_NAMES[b])] = (posed_joints[:, b] - posed_joints[:, a], clip)
    return out


def degrees_between(u, v):
    cosine = np.sum(u * v, axis=-1) / np.linalg.norm(u, axis=-1) / np.linalg.norm(v, axis=-1)
    return np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))


def free_frames(onto, joint, frames):
    """(F,) bool: frames where no joint from the root down to ``joint`` was clamped."""
    chain, index = [], JOINT_INDEX[joint]
    while index >= 0:
        chain.append(JOINT_NAMES[index])
        index = PARENTS[index]
    return ~onto.clamped[:, [JOINT_INDEX[j] for j in chain]].any(axis=1)


@pytest.mark.parametrize("mirror", [False, True])
@pytest.mark.parametrize("convention", clips.CONVENTIONS)
def test_every_rig_is_placed_by_its_names_and_points_where_the_clip_does(average, tmp_path, convention, mirror):
    clip, path = written(tmp_path, convention, average.joints, mirror)
    read = read_bvh(path)
    assert read.match.rig == EXPECTED_RIG.get(convention, convention)
    names, _, _, roles, _ = clips.rig_skeleton(convention, average.joints)
    expected = {JOINT_INDEX[r]: read.match.names.index(n) for n, r in zip(names, roles) if r in JOINT_INDEX}
    assert read.match.sources == expected
    assert read.match.unplaced == [n for i, n in enumerate(read.match.names) if i not in expected.values()]
    assert read.match.unsourced == [n for j, n in enumerate(JOINT_NAMES) if j not in expected]
    onto = clip_onto(average, read.motion, read.match)
    rotations = np.stack([p.rotations for p in onto.poses])
    translations = np.stack([p.translation for p in onto.poses])
    posed = forward_kinematics(average.joints, rotations, translations)[2]
    segments = segment_directions(read.match, average.joints, posed, read.motion.positions)
    compared = 0
    for (first, _), (mine, theirs) in segments.items():
        free = free_frames(onto, first, len(posed))
        assert degrees_between(mine, theirs)[free].max() < 1e-3, first
        compared += free.sum()
    assert len(segments) >= 9 and compared >= 0.8 * len(segments) * len(posed)


@pytest.mark.parametrize("convention", clips.CONVENTIONS)
def test_a_mirrored_clip_gives_the_mirrored_poses(average, tmp_path, convention):
    _, path = written(tmp_path, convention, average.joints)
    _, mirrored_path = written(tmp_path, convention, average.joints, mirror=True)
    poses = [clip_onto(average, read_bvh(p).motion, read_bvh(p).match).poses for p in (path, mirrored_path)]
    for pose, mirrored in zip(*poses):
        expected = mirror_pose(pose)
        assert np.abs(mirrored.rotations - expected.rotations).max() < 1e-9
        assert np.abs(mirrored.translation - expected.translation).max() < 1e-9


def test_a_clip_on_the_mannequins_own_rest_gives_its_rotations_back(average, tmp_path):
    hinge = joint_frames(average.joints)[JOINT_INDEX["L_Elbow"]][:, 0]
    bends = {
        ("L_Elbow", 2): axis_angle(hinge, np.radians(60.0)),
        ("R_Hip", 3): axis_angle([1.0, 0.0, 0.0], np.radians(-30.0)) @ axis_angle([0.0, 1.0, 0.0], np.radians(10)),
    }
    rotations = np.broadcast_to(np.eye(3), (5, 24, 3, 3)).copy()
    for (joint, frame), rotation in bends.items():
        rotations[frame, JOINT_INDEX[joint]] = rotation
    steps = np.array([[0.0, 0.0, 0.0], [0.0, -0.1, 0.0], [0.0, -0.2, 0.01], [0.0, -0.3, 0.0], [0.0, -0.4, 0.0]])
    names = [f"{j[2:]}_{j[0].lower()}" if j[1] == "_" else j for j in JOINT_NAMES]  # smpl-ish, unlisted spelling
    heads = average.joints.copy()
    ends = {i: np.array([0.0, -0.05, -heads[i][2]]) for i in (JOINT_INDEX["L_Foot"], JOINT_INDEX["R_Foot"])}
    clip = bvh.Clip(names, list(PARENTS), heads, rotations, {0: heads[0] + steps}, ends)
    read = read_bvh(bvh.write_bvh(tmp_path / "own.bvh", clip))
    onto = clip_onto(average, read.motion, read.match)
    assert np.abs(np.stack([p.rotations for p in onto.poses]) - rotations).max() < 1e-6  # 6 digits in the file
    assert np.abs(np.stack([p.translation for p in onto.poses]) - steps).max() < 1e-6  # same hip height: scale 1
    assert onto.clamps == []


def test_a_t_pose_clip_shows_a_t_pose(average, tmp_path):
    """A clip resting in a T-pose (CMU's, Mixamo's) is followed by bone directions: its rest frame puts the
    mannequin's arms horizontal."""
    clip = clips.convention_clip("mixamo", average.joints, frames=2, stretch=False)
    clip.rotations[:] = np.eye(3)
    read = read_bvh(bvh.write_bvh(tmp_path / "t.bvh", clip))
    pose = clip_onto(average, read.motion, read.match).poses[0]
    posed = forward_kinematics(average.joints, pose.rotations, pose.translation)[2]
    for side in "LR":
        arm = posed[JOINT_INDEX[f"{side}_Wrist"]] - posed[JOINT_INDEX[f"{side}_Shoulder"]]
        assert abs(arm[2]) < 1e-5 * np.linalg.norm(arm) and abs(arm[1]) < 1e-5  # horizontal, coronal


def test_the_root_follows_the_clip_scaled_by_the_hip_heights(average, tmp_path):
    """A clip 1.25 times as tall walking 1 m: the mannequin walks 0.8 m, and stands where the clip stands."""
    clip = clips.convention_clip("lafan1", average.joints, frames=6, stretch=False)
    clip.rotations[:] = np.eye(3)
    tall = bvh.Clip(
        clip.names,
        clip.parents,
        1.25 * clip.heads,
        clip.rotations,
        {0: 1.25 * clip.heads[0] + np.linspace(0, 1, 6)[:, None] * [0.0, -1.0, 0.0]},
        {i: 1.25 * e for i, e in clip.ends.items()},
    )
    read = read_bvh(bvh.write_bvh(tmp_path / "tall.bvh", tall))
    onto = clip_onto(average, read.motion, read.match)
    path = np.stack([p.translation for p in onto.poses])
    assert np.abs(path - np.linspace(0, 0.8, 6)[:, None] * [0.0, -1.0, 0.0]).max() < 1e-5
    assert np.abs(onto.lowest).max() < 1e-5 and "stays on the floor" in onto.floor_line()


def test_the_feet_against_the_floor_are_said_and_held_on_request(average, tmp_path):
    clip = clips.convention_clip("lafan1", average.joints, frames=8, stretch=False)
    clip.rotations[:] = np.eye(3)
    clip.positions[0] = clip.heads[0] + np.array([0.0, 0.0, -0.05]) * (np.arange(8) == 3)[:, None]
    read = read_bvh(bvh.write_bvh(tmp_path / "sink.bvh", clip))
    onto = clip_onto(average, read.motion, read.match)
    assert onto.lowest[3] == pytest.approx(-0.05, abs=1e-5) and np.abs(np.delete(onto.lowest, 3)).max() < 1e-5
    assert (
        onto.floor_line("; hint")
        == "feet: over the clip the lowest foot sinks up to 5.0 cm below the floor (frame 4); hint"
    )
    held = clip_onto(average, read.motion, read.match, keep_on_floor=True)
    posed_lowest = clips_lowest(average, held.poses)
    assert np.abs(posed_lowest).max() < 1e-9
    assert held.floor_line() == "feet: held on the floor in every frame (the root moved by up to 5.0 cm)"
    clip.positions[0] = clip.heads[0] + np.array([0.0, 0.0, 0.03]) * (np.arange(8) == 5)[:, None]
    read = read_bvh(bvh.write_bvh(tmp_path / "jump.bvh", clip))
    line = clip_onto(average, read.motion, read.match).floor_line()
    assert line == "feet: over the clip the lowest foot floats up to 3.0 cm above the floor (frame 6)"


def clips_lowest(mannequin, poses):
    from ellimann_addon.core.pose.clip import lowest_foot

    rotations = np.stack([p.rotations for p in poses])
    return lowest_foot(mannequin, mannequin.joints, rotations, np.stack([p.translation for p in poses]))


def test_clamps_are_summarised_per_joint_over_the_clip(average, tmp_path):
    """The knee bent backwards in 150 of 300 frames: one line for it, with the frames, the worst angle and the range."""
    clip = clips.convention_clip("smpl", average.joints, frames=300)
    knee = clip.names.index("left_knee")
    clip.rotations[:, knee] = [
        bvh.rotation_x(-10.0 - 30.0 * abs(np.sin(f / 20))) if f % 2 else np.eye(3) for f in range(300)
    ]
    read = read_bvh(bvh.write_bvh(tmp_path / "knees.bvh", clip))
    onto = clip_onto(average, read.motion, read.match)
    (summary,) = [c for c in onto.clamps if c.joint == "L_Knee"]
    low = summary.low
    worst_frame = max(range(1, 300, 2), key=lambda f: abs(np.sin(f / 20)))
    assert (summary.axis, summary.frames, summary.total, summary.frame) == ("x", 150, 300, worst_frame + 1)
    assert summary.worst == pytest.approx(-40.0 + 0.0 * low, abs=0.01)
    assert str(summary).startswith("L_Knee about its x axis in 150 of 300 frames, worst -40.0 degrees (frame ")
    assert f"range {low:.0f} to " in str(summary)


def test_units_are_read_from_the_offsets_and_said(average, tmp_path):
    motions = {}
    for label, unit in (("metres", 1.0), ("centimetres", 0.01), ("millimetres", 0.001), ("inches", 0.0254)):
        clip = clips.convention_clip("rokoko", average.joints, frames=4)
        clip.unit = unit
        read = read_bvh(bvh.write_bvh(tmp_path / f"{label}.bvh", clip))
        assert read.units == label and f"units: {label}" in read.lines()[0]
        motions[label] = read.motion
    for motion in motions.values():
        assert np.abs(motion.positions - motions["metres"].positions).max() < 2e-5
        assert np.abs(motion.rotations - motions["metres"].rotations).max() < 1e-6
    cmu = read_bvh(written(tmp_path, "cmu", average.joints)[1])
    assert cmu.units.startswith("CMU units")


def test_resampling_keeps_the_time_and_interpolates_between_frames(average, tmp_path):
    clip = clips.convention_clip("cmu", average.joints, frames=10)
    clip.frame_time = 1.0 / 30.0
    path = bvh.write_bvh(tmp_path / "c.bvh", clip)
    original, doubled = read_bvh(path), read_bvh(path, fps=60)
    assert doubled.motion.frames == 19 and doubled.motion.fps == 60
    assert np.abs(doubled.motion.rotations[::2] - original.motion.rotations).max() < 1e-4
    halfway = np.swapaxes(doubled.motion.rotations[1], -1, -2) @ original.motion.rotations[1]
    before = np.swapaxes(original.motion.rotations[0], -1, -2) @ doubled.motion.rotations[1]
    angle = lambda r: np.degrees(np.arccos(np.clip((np.trace(r, axis1=-2, axis2=-1) - 1) / 2, -1, 1)))  # noqa: E731
    assert np.abs(angle(halfway) - angle(before)).max() < 1e-3  # slerp: half way in angle
    assert "60 fps (resampled from 10 frames at 30 fps)" in doubled.lines()[0]
    with pytest.raises(ElliMannError, match="fps: must be a number from 1 to 240"):
        read_bvh(path, fps=500)


def test_the_names_say_side_and_part():
    assert name_words("mixamorig:LeftUpLeg") == ("L", ["up", "leg"])
    assert name_words("thigh_l")[0] == name_words("l_thigh")[0] == name_words("Thigh.L")[0] == "L"
    assert name_words("RHipJoint")[0] == "R" and name_words("RIGHTFOREARM") == ("R", ["forearm"])
    parts = {
        "LeftUpLeg": "Hip",
        "thigh.L": "Hip",
        "upperleg01.L": "Hip",
        "l_shin": "Knee",
        "calf_l": "Knee",
        "LeftLowLeg": "Knee",
        "LeftFoot": "Ankle",
        "ball_l": "Foot",
        "LeftCollar": "Collar",
        "clavicle_l": "Collar",
        "LeftUpArm": "Shoulder",
        "upper_arm.L": "Shoulder",
        "LeftForeArm": "Elbow",
        "lowerarm_l": "Elbow",
        "LeftLowArm": "Elbow",
        "wrist.L": "Wrist",
        "LeftLeg": "leg",
        "LeftArm": "arm",
        "LeftShoulder": "shoulder",
        "LHipJoint": "hip",
        "upperarm_twist_01_l": "skip",
        "LeftToe_End": "skip",
        "LeftHandIndex1": "finger",
    }
    assert {name: bone_part(name)[1] for name in parts} == parts
    assert [bone_part(n) for n in ("Hips", "LowerBack", "Neck1", "head", "root")] == [
        (None, "Pelvis"),
        (None, "spine"),
        (None, "Neck"),
        (None, "Head"),
        (None, "root"),
    ]


def test_every_listed_map_reaches_only_joints_and_ignores_case_and_namespace():
    for rig, names in RIG_NAME_MAPS.items():
        assert set(names.values()) <= set(JOINT_NAMES), rig
        if rig not in ("biovision", "lafan1", "rokoko"):  # they have no fingers (Biovision: no toes, one chest)
            assert set(names.values()) == set(JOINT_NAMES), rig
    assert joint_of_bone("mixamo", "mixamorig1:LeftForeArm") == "L_Elbow"
    assert joint_of_bone("unreal", "Armature|CALF_L") == "L_Knee"
    assert joint_of_bone("smpl", "m_avg_L_Hip") == joint_of_bone("smpl", "left_hip") == "L_Hip"
    assert joint_of_bone("mixamo", "mixamorig:Tail") is None


def test_the_chain_places_an_unnamed_knee_and_a_rig_can_be_forced(average, tmp_path):
    names = ["Hips", "thigh.L", "Bone.L", "foot.L", "thigh.R", "Bone.R", "foot.R", "Spine", "Neck", "Head"]
    parents = [-1, 0, 1, 2, 0, 4, 5, 0, 7, 8]
    match = match_bones(names, parents)
    assert match.rig == BY_NAMES and match.sources[JOINT_INDEX["L_Knee"]] == 2 and match.stiff_line() is None
    mixamo = ["Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "Spine", "LeftShoulder", "LeftArm", "LeftForeArm"]
    forced = match_bones(mixamo, [-1, 0, 1, 2, 0, 4, 5, 6], "cmu")
    assert forced.rig == "cmu" and JOINT_INDEX["Spine2"] in forced.sources  # CMU's Spine is Spine2
    with pytest.raises(ElliMannError, match="no limb of the 3 bones of the clip .* is in the Unreal"):
        match_bones(["Hips", "Spine", "Head"], [-1, 0, 1], "unreal")


def test_a_limb_without_its_middle_joint_is_said_to_not_bend():
    names = ["Hips", "LeftUpLeg", "LeftFoot", "RightUpLeg", "RightLeg", "RightFoot", "Spine", "Head"]
    match = match_bones(names, [-1, 0, 1, 0, 3, 4, 0, 6])
    assert match.stiff == {"L_Knee": ("L_Hip", "L_Ankle")}
    assert match.stiff_line() == "will not bend, the clip has no bone for them: L_Knee (between L_Hip and L_Ankle)"
    assert "L_Knee" in match.lines()[-1] and "R_Knee" not in match.lines()[-1]


def test_a_clip_without_a_known_limb_is_refused_naming_its_bones():
    with pytest.raises(ElliMannError) as refused:
        match_bones(["Wurzel", "Bein", "Fuss"], [-1, 0, 1], source="unknown.bvh")
    assert str(refused.value) == (
        "bones: no limb recognised among the 3 bones of unknown.bvh (Wurzel, Bein, Fuss): no listed rig's names "
        "(biovision, cmu, mixamo, lafan1, makehuman, smpl, unreal5, unreal, rokoko) and no side and part in a name "
        "(LeftUpLeg, thigh_l, upperarm.L, ...)"
    )
