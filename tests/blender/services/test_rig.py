"""The armature of a mannequin in Blender: bone names and heads, pieces following their bones, limits enforced
exactly as the core clamps, the standard poses and the walk action, rest, undo, refusals."""

import bpy
import numpy as np
import pytest
from mathutils import Matrix

from devkit.blender_scene import state
from ellimann_addon.blender.bridge.convert import objects_recursive, read_joints, rig_object
from ellimann_addon.blender.services.rig import MODIFIER_NAME, action_fcurves, apply_pose
from ellimann_addon.blender.services.scene import add_mannequin
from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.skeleton import JOINT_INDEX, JOINT_NAMES, bone_name, joint_frames, limits
from ellimann_addon.core.pose.kinematics import Pose, axis_angle, clamp_pose, forward_kinematics
from ellimann_addon.core.pose.standard import WALK_FPS, standard_motion, standard_pose
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER
from ellimann_addon.core.synthesis.shipped import FEMALE_FINE_SET, FEMALE_SET, SHIPPED_SETS

TOLERANCE = 2e-5  # m: Blender evaluates in single precision


@pytest.fixture(scope="module", params=[FEMALE_SET])
def average(request):
    """The Average RM of the paper's 40; of the fine topology too where the topology matters (every part on a bone:
    the rig takes both)."""
    mannequin = Mannequin.load(SHIPPED_SETS[request.param] / "average.json")
    assert mannequin.joints is not None
    return mannequin


@pytest.fixture
def rigged(average):
    """The Average RM with cushions, rigged with Add Armature (the active object one of its pieces)."""
    collection = add_mannequin(average, cushions=True)
    bpy.context.view_layer.objects.active = next(o for o in collection.objects if o.ellimann.kind == "ELLIPSOID")
    assert bpy.ops.ellimann.add_armature() == {"FINISHED"}
    return collection


def evaluated_world(obj):
    """World vertices (V, 3) of an object as Blender shows it (its modifiers applied)."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mesh = obj.evaluated_get(depsgraph).to_mesh()
    try:
        co = np.array([v.co[:] for v in mesh.vertices])
    finally:
        obj.evaluated_get(depsgraph).to_mesh_clear()
    matrix = np.array(obj.matrix_world)
    return co @ matrix[:3, :3].T + matrix[:3, 3]


def rest_world(obj):
    matrix = np.array(obj.matrix_world)
    return np.array([v.co[:] for v in obj.data.vertices]) @ matrix[:3, :3].T + matrix[:3, 3]


@pytest.mark.parametrize("average", [FEMALE_SET, FEMALE_FINE_SET], indirect=True)
def test_bones_are_the_smpl_joints_and_every_piece_is_bound(rigged, average):
    rig = rig_object(rigged)
    assert sorted(b.name for b in rig.data.bones) == sorted(JOINT_NAMES)
    heads = np.array([rig.data.bones[name].head_local for name in JOINT_NAMES])
    assert np.abs(heads - average.joints).max() < 1e-6
    parents = {b.name: b.parent.name if b.parent else None for b in rig.data.bones}
    assert parents["L_Elbow"] == "L_Shoulder" and parents["Pelvis"] is None
    bones = {p.name: bone_name(p) for p in average.topology}
    for obj in objects_recursive(rigged):
        if not obj.ellimann.is_part:
            continue
        assert obj.parent == rig and obj.modifiers[0].name == MODIFIER_NAME and obj.modifiers[0].object == rig
        groups = {g.name for g in obj.vertex_groups}
        if obj.ellimann.kind == "ELLIPSOID":
            assert groups == {bones[obj.ellimann.part_name]}
            assert all(len(v.groups) == 1 and v.groups[0].weight == 1.0 for v in obj.data.vertices)
        else:  # a cushion: its pieces' bones, every vertex on exactly one of them, fully
            assert groups == {bones[obj.ellimann.part_name], bones[obj.ellimann.partner]}
            assert all(len(v.groups) == 1 and v.groups[0].weight == 1.0 for v in obj.data.vertices)
    assert np.abs(read_joints(rigged) - average.joints).max() < 1e-6  # kept in single precision


def test_a_piece_follows_its_rotated_bone(rigged, average):
    """A 90 degree elbow flexion about its hinge moves the forearm (and the wrist) as forward kinematics says,
    and nothing above the elbow."""
    rig = rig_object(rigged)
    elbow = JOINT_INDEX["L_Elbow"]
    hinge = joint_frames(average.joints)[elbow][:, 0]
    pose = Pose()
    pose.rotations[elbow] = axis_angle(hinge, np.radians(90.0))
    pieces = {o.ellimann.part_name: o for o in rigged.objects if o.ellimann.kind == "ELLIPSOID"}
    forearm, upper = pieces["3.b Forearm.L"], pieces["3.a Upper Arm.L"]
    rest_forearm, rest_upper = rest_world(forearm), rest_world(upper)
    apply_pose(rig, pose)
    bpy.context.view_layer.update()
    rotation = axis_angle(hinge, np.radians(90.0))
    joint = average.joints[elbow]
    assert np.abs(evaluated_world(forearm) - ((rest_forearm - joint) @ rotation.T + joint)).max() < TOLERANCE
    assert np.abs(evaluated_world(upper) - rest_upper).max() < TOLERANCE
    wrist = average.joints[JOINT_INDEX["L_Wrist"]]
    posed_wrist = np.array(rig.matrix_world @ rig.pose.bones["L_Wrist"].head)
    assert np.abs(posed_wrist - (joint + rotation @ (wrist - joint))).max() < TOLERANCE
    # The objects' own matrices stay the rest pose: m_T is the rest pose's.
    assert (
        np.abs(np.array(forearm.matrix_world)[:3, 3] - average.center[average.topology.index["3.b Forearm.L"]]).max()
        < 1e-6
    )


@pytest.mark.parametrize(
    "joint, angles",
    [
        ("L_Knee", (-30.0, 0.0, 0.0)),
        ("L_Knee", (175.0, 10.0, 0.0)),
        ("R_Hip", (40.0, -60.0, 70.0)),
        ("L_Elbow", (10.0, 5.0, 0.0)),
    ],
)
def test_limits_are_enforced_as_the_core_clamps(rigged, average, joint, angles):
    """A rotation beyond a joint's range, typed into the bone, is shown clamped exactly as
    core.pose.kinematics.clamp_pose
    clamps it (the Limit Rotation constraint works in the bone's axes, the limit frame relabelled)."""
    rig = rig_object(rigged)
    index = JOINT_INDEX[joint]
    frame = joint_frames(average.joints)[index]
    a, b, c = np.radians(angles)
    local = (
        frame
        @ axis_angle([1.0, 0.0, 0.0], a)
        @ axis_angle([0.0, 1.0, 0.0], b)
        @ axis_angle([0.0, 0.0, 1.0], c)
        @ frame.T
    )
    pose = Pose()
    pose.rotations[index] = local
    clamped, reports = clamp_pose(pose, average.joints)
    assert reports and all(r.joint == joint for r in reports)  # each case is beyond a limit
    apply_pose(rig, pose)  # the bone's own rotation is what was typed ...
    bpy.context.view_layer.update()
    bone = rig.pose.bones[joint]
    shown = np.array(bone.matrix)[:3, :3] @ np.array(bone.bone.matrix_local)[:3, :3].T  # ... what it shows, clamped
    world, _, _ = forward_kinematics(average.joints, clamped.rotations)
    assert np.abs(shown - world[index]).max() < 1e-5


@pytest.mark.parametrize("average", [FEMALE_SET, FEMALE_FINE_SET], indirect=True)
def test_standard_poses_one_click_each_and_back_to_rest(rigged, average):
    rig = rig_object(rigged)
    shin = next(o for o in rigged.objects if o.ellimann.part_name == "6.a Calf.L")
    rest = rest_world(shin)
    for name in ("t_pose", "attention", "sit"):
        assert bpy.ops.ellimann.apply_pose(pose=name) == {"FINISHED"}
        bpy.context.view_layer.update()
        pose = standard_pose(name, average.joints)
        world, offset, _ = forward_kinematics(average.joints, pose.rotations, pose.translation)
        knee = JOINT_INDEX["L_Knee"]
        assert np.abs(evaluated_world(shin) - (rest @ world[knee].T + offset[knee])).max() < TOLERANCE
    assert bpy.ops.ellimann.rest_pose() == {"FINISHED"}
    bpy.context.view_layer.update()
    assert np.abs(evaluated_world(shin) - rest).max() < TOLERANCE
    assert rig.animation_data is None or rig.animation_data.action is None


@pytest.mark.parametrize("average", [FEMALE_SET, FEMALE_FINE_SET], indirect=True)
def test_measurements_stay_the_rest_poses(rigged):
    assert bpy.ops.ellimann.measure_mannequin() == {"FINISHED"}
    rest = tuple(rigged.ellimann.measured)
    assert bpy.ops.ellimann.apply_pose(pose="sit") == {"FINISHED"}
    assert bpy.ops.ellimann.measure_mannequin() == {"FINISHED"}
    assert tuple(rigged.ellimann.measured) == rest


def test_walk_is_a_looping_action_on_the_timeline(rigged, average):
    rig = rig_object(rigged)
    assert bpy.ops.ellimann.apply_pose(pose="walk") == {"FINISHED"}
    scene = bpy.context.scene
    frames = standard_motion("walk", average.joints)
    assert (scene.frame_start, scene.frame_end, scene.render.fps) == (1, len(frames), WALK_FPS)
    action = rig.animation_data.action
    curves = action_fcurves(action, rig)
    assert len(curves) == 4 * len(JOINT_NAMES) + 3  # a quaternion per bone, the root's location
    assert all(len(c.keyframe_points) == len(frames) + 1 and c.modifiers[0].type == "CYCLES" for c in curves)
    knee = rig.pose.bones["L_Knee"]
    for frame in (1, 7, 13):
        scene.frame_set(frame)
        expected = forward_kinematics(average.joints, frames[frame - 1].rotations, frames[frame - 1].translation)
        shown = np.array(rig.matrix_world @ knee.head)
        assert np.abs(shown - expected[2][JOINT_INDEX["L_Knee"]]).max() < TOLERANCE
    scene.frame_set(1)
    first = np.array([np.array(b.matrix) for b in rig.pose.bones])
    scene.frame_set(1 + len(frames))  # one cycle on: the same pose, moved on by one stride
    again = np.array([np.array(b.matrix) for b in rig.pose.bones])
    assert np.abs(again[:, :3, :3] - first[:, :3, :3]).max() < 1e-5
    assert np.abs(again[:, :3, 3] - first[:, :3, 3] - (again[0, :3, 3] - first[0, :3, 3])).max() < 1e-5
    assert again[0, 1, 3] < first[0, 1, 3] - 0.5  # walked forward (-Y) by a stride


def test_a_mannequin_without_joints_cannot_be_rigged(average):
    collection = add_mannequin(average.copy(joints=None))
    bpy.context.view_layer.objects.active = next(iter(collection.objects))
    assert not bpy.ops.ellimann.add_armature.poll()
    before = state()
    from ellimann_addon.blender.services.rig import build_rig

    with pytest.raises(ElliMannError, match="has no joints"):
        build_rig(collection, average.copy(joints=None))
    assert state() == before


def test_rebuilding_replaces_the_armature(rigged, average):
    assert bpy.ops.ellimann.add_armature() == {"FINISHED"}
    assert len([o for o in bpy.data.objects if o.type == "ARMATURE"]) == 1
    assert len([m for m in bpy.data.meshes if m.get("ellimann_unit_sphere_bone")]) == len(
        {bone_name(p) for p in average.topology}
    )


def test_a_bone_typed_into_directly_moves_its_pieces(rigged):
    """What a user does in Pose Mode: rotate a bone, the pieces on it follow."""
    rig = rig_object(rigged)
    hand = next(o for o in rigged.objects if o.ellimann.part_name == "4.a Hand.L")
    rest = rest_world(hand)
    bone = rig.pose.bones["L_Wrist"]
    bone.rotation_quaternion = Matrix(np.eye(3).tolist()).to_quaternion()
    bone.rotation_quaternion = (0.9659, 0.2588, 0.0, 0.0)  # 30 degrees about the bone's x
    bpy.context.view_layer.update()
    assert np.abs(evaluated_world(hand) - rest).max() > 0.01


def test_rebuilt_cushions_are_bound_again(rigged, average):
    assert bpy.ops.ellimann.build_cushions(subdivisions=1) == {"FINISHED"}
    rig = rig_object(rigged)
    cushions = [o for o in objects_recursive(rigged) if o.ellimann.kind == "CUSHION"]
    assert len(cushions) == len(average.topology.cushion_pairs)
    assert all(c.modifiers[0].object == rig and c.parent == rig and len(c.vertex_groups) for c in cushions)


def test_the_pose_panel_shows_the_poses_and_the_active_bones_limits(rigged, average):
    from types import SimpleNamespace

    from devkit.ui_recorder import draw_panel
    from ellimann_addon.blender import ids
    from ellimann_addon.blender.features.pose.panel import ELLIMANN_PT_pose

    rig = rig_object(rigged)
    context = SimpleNamespace(
        scene=bpy.context.scene,
        active_object=rig,
        collection=rigged,
        mode="POSE",
        active_pose_bone=rig.pose.bones["L_Knee"],
    )
    recorder = draw_panel(ELLIMANN_PT_pose, context)
    assert {ids.APPLY_POSE, ids.REST_POSE, ids.IMPORT_BVH, ids.ADD_ARMATURE} <= set(recorder.operators())
    labels = recorder.labels()
    assert "Measurements are the rest pose's" in labels and any(t.startswith("L_Knee limits") for t in labels)
    low, high = np.degrees(limits(average.joints)[JOINT_INDEX["L_Knee"], 0])
    assert f"X: {low:.0f} to {high:.0f}" in labels and labels.count("Y: locked") + labels.count("Z: locked") == 2


def test_a_mannequin_outside_the_view_layer_is_refused_unchanged(rigged, average):
    from ellimann_addon.blender.services.rig import build_rig

    layer = next(lc for lc in bpy.context.view_layer.layer_collection.children if lc.collection == rigged)
    layer.exclude = True
    before = state()
    with pytest.raises(ElliMannError, match="is not in view layer"):
        build_rig(rigged, average)
    assert state() == before


def test_synthesize_rigs_a_mannequin_of_references_with_joints():
    props = bpy.context.scene.ellimann_synthesis
    props.references = str(REFERENCE_FOLDER)  # the shipped RMs carry joints
    props.output = "CUSHIONS"
    assert bpy.ops.ellimann.synthesize_mannequin() == {"FINISHED"}
    collection = props.target
    rig = rig_object(collection)
    assert rig is not None and sorted(b.name for b in rig.data.bones) == sorted(JOINT_NAMES)
    assert all(o.modifiers[0].object == rig for o in objects_recursive(collection) if o.ellimann.is_part)
    bpy.context.view_layer.objects.active = rig
    assert bpy.ops.ellimann.apply_pose(pose="sit") == {"FINISHED"}
