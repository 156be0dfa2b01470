"""BVH motion onto a mannequin: Blender's importer, the bone-name maps (CMU, Mixamo with and without its prefix,
MakeHuman), rest poses that differ from the mannequin's, clamping reported by joint and frame, and refusals that
change nothing. The clips are written here (devkit.bvh), not downloaded."""

import bpy
import numpy as np
import pytest

from devkit import bvh
from devkit.blender_scene import state
from ellimann_addon.blender.bridge.convert import rig_object
from ellimann_addon.blender.features.pose.bvh import motion_onto
from ellimann_addon.blender.services.bvh import bvh_header, sample_bvh
from ellimann_addon.blender.services.scene import add_mannequin
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.skeleton import JOINT_INDEX, JOINT_NAMES, PARENTS, RIG_NAME_MAPS, joint_frames
from ellimann_addon.core.pose.kinematics import Pose, axis_angle, forward_kinematics, limit_reports
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

STEPS = np.array([[0.0, 0.0, 0.0], [0.0, -0.1, 0.0], [0.0, -0.2, 0.01], [0.0, -0.3, 0.0], [0.0, -0.4, 0.0]])


@pytest.fixture(scope="module")
def average():
    return Mannequin.load(REFERENCE_FOLDER / "average.json")


@pytest.fixture
def rigged(average):
    collection = add_mannequin(average)
    bpy.context.view_layer.objects.active = next(iter(collection.objects))
    assert bpy.ops.ellimann.add_armature() == {"FINISHED"}
    return collection


def bends(average):
    """Rotations within the limits: a 60 degree elbow flexion about its hinge, a hip flexed and abducted."""
    hinge = joint_frames(average.joints)[JOINT_INDEX["L_Elbow"]][:, 0]
    return {
        ("L_Elbow", 2): axis_angle(hinge, np.radians(60.0)),
        ("R_Hip", 3): axis_angle([1.0, 0.0, 0.0], np.radians(-30.0)) @ axis_angle([0.0, 1.0, 0.0], np.radians(10)),
    }


def write_clip(path, average, style, frames=5, extra=None):
    motion = {**bends(average), **(extra or {})}
    clip = bvh.clip_for(JOINT_NAMES, PARENTS, average.joints, style, frames, motion, STEPS[:frames])
    return bvh.write_bvh(path, *clip)


@pytest.mark.parametrize("style", ["cmu", "mixamo"])
def test_a_clip_on_the_mannequins_own_rest_gives_its_rotations_back(average, tmp_path, style):
    path = write_clip(tmp_path / f"{style}.bvh", average, style)
    poses, reports, key, clip = motion_onto_scene(average, path)
    assert key == style
    assert len(poses) == 5 and clip.fps == pytest.approx(24.0, rel=1e-4)
    expected = np.broadcast_to(np.eye(3), (5, 24, 3, 3)).copy()
    for (joint, frame), rotation in bends(average).items():
        expected[frame, JOINT_INDEX[joint]] = rotation
    error = np.abs(np.stack([p.rotations for p in poses]) - expected).max(axis=(2, 3))
    assert error.max() < 1e-5, [(f, JOINT_NAMES[j]) for f, j in zip(*np.nonzero(error > 1e-5))]
    assert np.abs(np.stack([p.translation for p in poses]) - STEPS).max() < 1e-5  # same hip height: scale 1
    assert reports == [] and not limit_reports(poses[2], average.joints)


def motion_onto_scene(average, path):
    collection = add_mannequin(average)
    return motion_onto(collection, path)


def test_a_t_pose_clip_shows_a_t_pose(average, tmp_path):
    """A clip resting in a T-pose (CMU's and Mixamo's) is followed by bone directions: its rest frame puts the
    mannequin's arms horizontal."""
    heads = average.joints.copy()
    for side, sign in (("L", 1.0), ("R", -1.0)):
        shoulder = heads[JOINT_INDEX[f"{side}_Shoulder"]]
        for k, joint in enumerate(("Elbow", "Wrist", "Hand"), start=1):
            heads[JOINT_INDEX[f"{side}_{joint}"]] = shoulder + sign * np.array([0.15 * k, 0.0, 0.0])
    clip = bvh.clip_for(JOINT_NAMES, PARENTS, heads, "mixamo", 2)
    path = bvh.write_bvh(tmp_path / "t.bvh", *clip)
    poses, _, _, _ = motion_onto_scene(average, path)
    posed = forward_kinematics(average.joints, poses[0].rotations, poses[0].translation)[2]
    for side in "LR":
        arm = posed[JOINT_INDEX[f"{side}_Wrist"]] - posed[JOINT_INDEX[f"{side}_Shoulder"]]
        assert abs(arm[2]) < 1e-4 * np.linalg.norm(arm) + 1e-6 and abs(arm[1]) < 1e-4  # horizontal, coronal


def test_import_operator_clamps_and_reports_joint_and_frame(rigged, average, tmp_path):
    hyperextended = {("L_Knee", 3): axis_angle([1.0, 0.0, 0.0], np.radians(-40.0))}  # a knee bent backwards
    path = write_clip(tmp_path / "knee.bvh", average, "cmu", extra=hyperextended)
    assert bpy.ops.ellimann.import_bvh(filepath=str(path)) == {"FINISHED"}
    status = bpy.context.scene.ellimann_pose.status
    assert "clamped" in status and "frame 4" in status and "L_Knee" in status  # BVH frame 3 is scene frame 4
    rig = rig_object(rigged)
    scene = bpy.context.scene
    assert (scene.frame_start, scene.frame_end) == (1, 5)
    scene.frame_set(4)
    knee = rig.pose.bones["L_Knee"]
    shown = np.array(knee.matrix)[:3, :3] @ np.array(knee.bone.matrix_local)[:3, :3].T
    hip = rig.pose.bones["L_Hip"]
    parent = np.array(hip.matrix)[:3, :3] @ np.array(hip.bone.matrix_local)[:3, :3].T
    assert not limit_reports(Pose(rotations=_with(JOINT_INDEX["L_Knee"], parent.T @ shown)), average.joints)


def _with(index, rotation):
    rotations = np.broadcast_to(np.eye(3), (24, 3, 3)).copy()
    rotations[index] = rotation
    return rotations


def test_a_clip_with_no_known_bone_changes_nothing(rigged, tmp_path):
    names = ["Wurzel", "Bein", "Fuss"]
    path = bvh.write_bvh(
        tmp_path / "unknown.bvh",
        names,
        [-1, 0, 1],
        np.array([[0, 0, 1], [0, 0, 0.5], [0, 0, 0.1]]),
        np.broadcast_to(np.eye(3), (2, 3, 3, 3)),
        np.zeros((2, 3)),
    )
    before = state()
    with pytest.raises(RuntimeError, match="none of the 3 bones of unknown.bvh"):
        bpy.ops.ellimann.import_bvh(filepath=str(path))
    assert state() == before


@pytest.mark.parametrize(
    "text, message",
    [("not a clip\n", "is not a BVH clip"), ("HIERARCHY\nMOTION\nFrames: 0\nFrame Time: 0.04\n", "has no bones")],
)
def test_a_file_that_is_no_clip_is_refused_in_one_line(tmp_path, text, message):
    path = tmp_path / "bad.bvh"
    path.write_text(text)
    from ellimann_addon.core.errors import ElliMannError

    with pytest.raises(ElliMannError, match=message):
        bvh_header(path)


def test_mixamo_names_with_and_without_their_prefix_and_makehuman_names_are_known():
    assert RIG_NAME_MAPS["mixamo"]["LeftForeArm"] == "L_Elbow"
    from ellimann_addon.blender.features.pose.bvh import name_map

    assert name_map(["mixamorig:Hips", "mixamorig:LeftForeArm"])[1] == {
        "mixamorig:Hips": "Pelvis",
        "mixamorig:LeftForeArm": "L_Elbow",
    }
    assert name_map(["root", "lowerarm01.L", "upperleg01.R"])[0] == "makehuman"


def test_sampling_leaves_the_scene_as_it_was(rigged, average, tmp_path):
    path = write_clip(tmp_path / "c.bvh", average, "cmu")
    before = state()
    sample_bvh(path)
    assert state() == before
