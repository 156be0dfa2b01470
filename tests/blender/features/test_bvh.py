"""BVH motion in Blender: ElliMann's reading (core.formats.bvh, numpy) against Blender's own importer on every test
clip and its mirror image (the thighs, shins, upper arms, forearms and spine of the mannequin point where
Blender's import of the clip points them, wherever no limit was reached); the Import BVH operator (the same core
path) saying what it placed, what it clamped and where the feet went, holding them on the floor on request, and
changing nothing when it refuses; posed .glb and .blend files of a clip. The clips are written here
(devkit.clips), not downloaded."""

import bpy
import numpy as np
import pytest

from devkit import bvh, clips, gltf_skin, gltf_validator
from devkit.blender_bvh import blender_heads
from devkit.blender_scene import state
from ellimann_addon.blender.bridge.convert import rig_object
from ellimann_addon.blender.services.posing import write_posed
from ellimann_addon.blender.services.rig import action_fcurves
from ellimann_addon.blender.services.scene import add_mannequin
from ellimann_addon.core.formats.bvh import read_bvh
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.skeleton import JOINT_INDEX, JOINT_NAMES, PARENTS
from ellimann_addon.core.pose.clip import clip_onto
from ellimann_addon.core.pose.kinematics import forward_kinematics
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

# Each segment by the joint it starts at: thighs, shins, upper arms, forearms, and the spine's joints.
SEGMENTS = {
    "thighs": ("L_Hip", "R_Hip"),
    "shins": ("L_Knee", "R_Knee"),
    "upper arms": ("L_Shoulder", "R_Shoulder"),
    "forearms": ("L_Elbow", "R_Elbow"),
    "spine": ("Spine1", "Spine2", "Spine3"),
}
DIRECTION_ERRORS = {}  # (clip, mirrored) -> {segment: worst degrees}, printed by the last test for the docs


@pytest.fixture(scope="module")
def average():
    return Mannequin.load(REFERENCE_FOLDER / "average.json")


@pytest.fixture
def rigged(average):
    collection = add_mannequin(average)
    bpy.context.view_layer.objects.active = next(iter(collection.objects))
    assert bpy.ops.ellimann.add_armature() == {"FINISHED"}
    return collection


def degrees_between(u, v):
    cosine = np.sum(u * v, axis=-1) / np.linalg.norm(u, axis=-1) / np.linalg.norm(v, axis=-1)
    return np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))


def unclamped(onto, joint):
    """(F,) bool: the frames where no joint from the root down to ``joint`` was clamped."""
    chain = [joint]
    while PARENTS[chain[-1]] >= 0:
        chain.append(PARENTS[chain[-1]])
    return ~onto.clamped[:, chain].any(axis=1)


@pytest.mark.slow
@pytest.mark.parametrize("mirror", [False, True], ids=["clip", "mirrored"])
@pytest.mark.parametrize("convention", clips.CONVENTIONS)
def test_the_mannequin_points_where_blenders_import_of_the_clip_does(average, tmp_path, convention, mirror):
    clip = clips.convention_clip(convention, average.joints, mirror=mirror)
    path = bvh.write_bvh(tmp_path / f"{convention}.bvh", clip)
    read = read_bvh(path)
    blender = blender_heads(path)  # file units: directions only
    assert blender.shape == read.motion.positions.shape
    onto = clip_onto(average, read.motion, read.match)
    rotations = np.stack([p.rotations for p in onto.poses])
    posed = forward_kinematics(average.joints, rotations, np.stack([p.translation for p in onto.poses]))[2]
    errors, compared, total = {}, 0, 0
    for segment, starts in SEGMENTS.items():
        for name in starts:
            joint = JOINT_INDEX[name]
            end = read.match.segment_end(joint)
            if joint not in read.match.sources or end is None:
                continue
            theirs = blender[:, read.match.sources[end]] - blender[:, read.match.sources[joint]]
            free = unclamped(onto, joint)
            error = degrees_between(posed[:, end] - posed[:, joint], theirs)[free]
            errors[segment] = max(errors.get(segment, 0.0), float(error.max()) if len(error) else 0.0)
            compared, total = compared + free.sum(), total + len(free)
    DIRECTION_ERRORS[(convention, mirror)] = (errors, compared, total)
    assert set(errors) == set(SEGMENTS)
    assert max(errors.values()) < 0.01, errors  # Blender keeps float32: a few 1e-4 degrees
    assert compared >= 0.8 * total


@pytest.mark.slow
def test_direction_errors_table():
    """The table of docs/posing.md (run with -s to see it): the worst angle per clip and segment."""
    if not DIRECTION_ERRORS:
        pytest.skip("runs after the comparison tests")
    print("\n| clip | " + " | ".join(SEGMENTS) + " | segment-frames compared |")
    for (convention, mirror), (errors, compared, total) in DIRECTION_ERRORS.items():
        cells = " | ".join(f"{errors[s]:.1e}" for s in SEGMENTS)
        print(f"| {convention}{' (mirrored)' if mirror else ''} | {cells} | {compared} of {total} |")


def test_import_reports_clamps_per_joint_and_what_it_placed(rigged, average, tmp_path):
    path = bvh.write_bvh(tmp_path / "cmu.bvh", clips.convention_clip("cmu", average.joints))
    assert bpy.ops.ellimann.import_bvh(filepath=str(path)) == {"FINISHED"}
    lines = bpy.context.scene.ellimann_pose.status.splitlines()
    assert lines[0] == "cmu: 24 frames, CMU names; 2 joints clamped"
    assert lines[1].startswith("L_Knee x: 1/24 frames, worst -25\u00b0 (frame 13), range -10 to ")
    assert lines[2].startswith("R_Elbow x: 1/24 frames, worst -48\u00b0 (frame 13), range ")
    assert lines[3] == "not placed: LHipJoint, RHipJoint, Neck1, LThumb, RThumb"
    assert lines[4].startswith("feet: ") and lines[4].endswith(" cm from the floor")
    scene, rig = bpy.context.scene, rig_object(rigged)
    assert (scene.frame_start, scene.frame_end, scene.render.fps) == (1, 24, 30)
    action = rig.animation_data.action
    assert all(len(c.keyframe_points) == 24 for c in action_fcurves(action, rig))
    scene.frame_set(13)  # the clamped frame: the knee within its range
    knee, hip = rig.pose.bones["L_Knee"], rig.pose.bones["L_Hip"]
    local = np.array(hip.matrix)[:3, :3].T @ np.array(knee.matrix)[:3, :3]
    rest = np.array(hip.bone.matrix_local)[:3, :3].T @ np.array(knee.bone.matrix_local)[:3, :3]
    bend = np.degrees(np.arccos(np.clip((np.trace(rest.T @ local) - 1) / 2, -1, 1)))
    assert bend < 12.0  # the clip's -25 degrees clamped to the range's end (about -10)


def test_import_warns_of_a_limb_that_will_not_bend_and_holds_the_feet(rigged, tmp_path):
    names = ["Hips", "LeftUpLeg", "LeftFoot", "RightUpLeg", "RightLeg", "RightFoot", "Spine", "Head"]
    heads = np.array([[0, 0, 0.9], [0.1, 0, 0.85], [0.1, 0, 0.08], [-0.1, 0, 0.85], [-0.1, 0, 0.47], [-0.1, 0, 0.08]])
    heads = np.vstack([heads, [[0, 0, 1.2], [0, 0, 1.5]]])
    positions = {0: heads[0] + np.array([[0, 0, 0], [0, 0, -0.04]])}
    path = bvh.write_bvh(
        tmp_path / "stiff.bvh",
        bvh.Clip(names, list(range(-1, 7)), heads, np.broadcast_to(np.eye(3), (2, 8, 3, 3)), positions),
    )
    bpy.context.scene.ellimann_pose.keep_on_floor = True
    assert bpy.ops.ellimann.import_bvh(filepath=str(path)) == {"FINISHED"}
    status = bpy.context.scene.ellimann_pose.status
    assert "will not bend: L_Knee" in status.splitlines()[0]
    assert "will not bend: L_Knee (between L_Hip and L_Ankle)" in status.splitlines()
    assert status.splitlines()[-1].startswith("feet: ") and status.endswith("cm from the floor (held on it)")


def test_a_clip_with_no_known_limb_changes_nothing(rigged, tmp_path):
    path = bvh.write_bvh(
        tmp_path / "unknown.bvh",
        bvh.Clip(
            ["Wurzel", "Bein", "Fuss"],
            [-1, 0, 1],
            np.array([[0, 0, 1], [0, 0, 0.5], [0, 0, 0.1]]),
            np.broadcast_to(np.eye(3), (2, 3, 3, 3)),
            {0: np.array([[0, 0, 1.0], [0, 0, 1.0]])},
        ),
    )
    before = state()
    with pytest.raises(RuntimeError, match="no limb recognised among the 3 bones of unknown.bvh"):
        bpy.ops.ellimann.import_bvh(filepath=str(path))
    assert state() == before


def test_a_bad_file_changes_nothing(rigged, tmp_path):
    path = tmp_path / "bad.bvh"
    path.write_text("HIERARCHY\nROOT Hips\n{\nOFFSET 0 0\n")
    before = state()
    with pytest.raises(RuntimeError, match="clip bad.bvh: ends at line 4 where OFFSET's z should follow"):
        bpy.ops.ellimann.import_bvh(filepath=str(path))
    assert state() == before


@pytest.mark.slow
def test_a_clip_writes_a_skinned_glb_with_its_animation_and_a_blend_with_its_action(average, tmp_path):
    path = bvh.write_bvh(tmp_path / "walk.bvh", clips.convention_clip("mixamo", average.joints, frames=12))
    read = read_bvh(path)
    poses = clip_onto(average, read.motion, read.match, name=read.name).poses
    glb, blend = tmp_path / "walk.glb", tmp_path / "walk.blend"
    write_posed(average, poses, [glb, blend], fps=read.motion.fps)
    issues = gltf_validator.validate(glb)
    assert issues["numErrors"] == 0, gltf_validator.errors(issues)
    doc, binary = gltf_skin.read_glb(glb)
    (animation,) = doc["animations"]
    times = gltf_skin.accessor(doc, binary, animation["samplers"][0]["input"]).ravel()
    assert len(times) == 12 and times[-1] - times[0] == pytest.approx(11 / read.motion.fps, abs=1e-4)  # no loop
    assert {doc["nodes"][c["target"]["node"]]["name"] for c in animation["channels"]} == set(JOINT_NAMES)
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    collection = next(c for c in bpy.data.collections if c.ellimann.is_mannequin)
    rig = rig_object(collection)
    action = rig.animation_data.action
    assert action.name.endswith("walk.bvh") and all(len(c.keyframe_points) == 12 for c in action_fcurves(action, rig))
    assert not any(m.type == "CYCLES" for c in action_fcurves(action, rig) for m in c.modifiers)
    assert (bpy.context.scene.frame_start, bpy.context.scene.frame_end) == (1, 12)


def test_the_command_line_writes_a_clip_to_blend_and_glb(average, tmp_path, capsys):
    from devkit.cli_runs import run

    clip = bvh.write_bvh(tmp_path / "walk.bvh", clips.convention_clip("lafan1", average.joints, frames=10))
    rest = tmp_path / "rest.json"
    average.save(rest)
    for out in ("walk.blend", "walk.glb"):
        code, stdout, _ = run(
            ["pose", str(rest), "--pose", str(clip), "--fps", "20", "-o", str(tmp_path / out)], capsys
        )
        assert code == 0 and "(7 frames)" in stdout  # 10 frames at 30 fps: 0.3 s, 7 frames at 20
    doc, binary = gltf_skin.read_glb(tmp_path / "walk.glb")
    times = gltf_skin.accessor(doc, binary, doc["animations"][0]["samplers"][0]["input"]).ravel()
    assert len(times) == 7 and times[-1] - times[0] == pytest.approx(0.3, abs=1e-4)
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "walk.blend"))
    scene = bpy.context.scene
    assert (scene.frame_end, scene.render.fps / scene.render.fps_base) == (7, pytest.approx(20.0))
