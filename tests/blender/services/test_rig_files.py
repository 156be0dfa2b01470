"""Posed files: a .glb skinned glTF the Khronos validator accepts with no error, its skin posing the pieces where
Blender shows them, the walk as an animation; a .blend with the armature, bound pieces and the walk action;
refusals before anything is written."""

import bpy
import numpy as np
import pytest

from devkit import gltf_skin, gltf_validator
from ellimann_addon.blender.bridge.convert import objects_recursive, rig_object
from ellimann_addon.blender.services.posing import write_posed
from ellimann_addon.blender.services.rig import action_fcurves
from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.skeleton import JOINT_NAMES, bone_name
from ellimann_addon.core.pose.motion import clamped_motion
from ellimann_addon.core.pose.standard import standard_motion
from ellimann_addon.core.synthesis.shipped import FEMALE_FINE_SET, FEMALE_SET, SHIPPED_SETS

Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # glTF (x, y, z) -> Blender


@pytest.fixture(scope="module", params=[FEMALE_SET])
def average(request):
    """The Average RM of the paper's 40; of the fine topology too for the posed .obj and .blend (its glTF: the
    rest pose with cushions, tests/blender/features/test_fine.py)."""
    return Mannequin.load(SHIPPED_SETS[request.param] / "average.json")


def write_mannequin(mannequin, paths, cushions=False, pose="a_pose"):
    """What ``ellimann synth ... --pose NAME -o x.glb`` does for the Blender formats."""
    frames = clamped_motion(pose, mannequin.joints)[0] if mannequin.joints is not None else [None]
    return write_posed(mannequin, frames, paths, cushions)


def evaluated_world(obj):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mesh = obj.evaluated_get(depsgraph).to_mesh()
    co = np.array([v.co[:] for v in mesh.vertices])
    obj.evaluated_get(depsgraph).to_mesh_clear()
    matrix = np.array(obj.matrix_world)
    return co @ matrix[:3, :3].T + matrix[:3, 3]


def the_collection():
    return next(c for c in bpy.data.collections if c.ellimann.is_mannequin)


@pytest.mark.slow
def test_a_posed_glb_is_valid_and_skinned_where_blender_shows_it(average, tmp_path):
    path = tmp_path / "sit.glb"
    write_mannequin(average, [path], cushions=True, pose="sit")
    issues = gltf_validator.validate(path)
    assert issues["numErrors"] == 0, gltf_validator.errors(issues)
    doc, binary = gltf_skin.read_glb(path)
    assert len(doc["skins"]) == 1 and {doc["nodes"][j]["name"] for j in doc["skins"][0]["joints"]} == set(JOINT_NAMES)
    collection = the_collection()
    bpy.context.view_layer.update()
    bones = {p.name: bone_name(p) for p in average.topology}
    checked = 0
    for obj in objects_recursive(collection):
        if not obj.ellimann.is_part or obj.hide_render:
            continue
        node = next(n for n in doc["nodes"] if n.get("name") == obj.name)
        primitive = doc["meshes"][node["mesh"]]["primitives"][0]
        joints = gltf_skin.accessor(doc, binary, primitive["attributes"]["JOINTS_0"]).astype(int)
        weights = gltf_skin.accessor(doc, binary, primitive["attributes"]["WEIGHTS_0"])
        skin_joints = [doc["nodes"][j]["name"] for j in doc["skins"][0]["joints"]]
        # Every vertex fully on one bone, the bone of its piece (of one of the two for a cushion).
        assert np.allclose(weights.max(axis=1), 1.0) and np.allclose(weights.sum(axis=1), 1.0)
        used = {skin_joints[j] for j in joints[np.arange(len(joints)), weights.argmax(axis=1)]}
        assert used <= {bones[obj.ellimann.part_name], bones.get(obj.ellimann.partner, "")}
        shown = gltf_skin.skinned_positions(doc, binary, obj.name) @ Y_UP_TO_Z_UP.T
        assert np.abs(shown - evaluated_world(obj)).max() < 1e-4
        checked += 1
    assert checked == len(average.topology.single_parts()) + len(average.topology.cushion_pairs)


@pytest.mark.slow
def test_the_walk_glb_holds_the_cycle_as_an_animation(average, tmp_path):
    path = tmp_path / "walk.glb"
    write_mannequin(average, [path], pose="walk")
    issues = gltf_validator.validate(path)
    assert issues["numErrors"] == 0, gltf_validator.errors(issues)
    doc, binary = gltf_skin.read_glb(path)
    (animation,) = doc["animations"]
    frames = len(standard_motion("walk", average.joints))
    times = gltf_skin.accessor(doc, binary, animation["samplers"][0]["input"]).ravel()
    assert len(times) == frames + 1 and abs(times[-1] - times[0] - 1.0) < 1e-4  # one second, looping
    targets = {doc["nodes"][c["target"]["node"]]["name"] for c in animation["channels"]}
    assert targets == set(JOINT_NAMES)


@pytest.mark.parametrize("average", [FEMALE_SET, FEMALE_FINE_SET], indirect=True)
def test_the_blend_holds_the_armature_bound_pieces_and_the_walk(average, tmp_path):
    path = tmp_path / "walk.blend"
    write_mannequin(average, [path], pose="walk")
    bpy.ops.wm.open_mainfile(filepath=str(path))
    collection = the_collection()
    rig = rig_object(collection)
    assert sorted(b.name for b in rig.data.bones) == sorted(JOINT_NAMES)
    assert all(o.modifiers[0].object == rig for o in collection.objects if o.ellimann.is_part)
    action = rig.animation_data.action
    frames = len(standard_motion("walk", average.joints))
    assert all(len(c.keyframe_points) == frames + 1 for c in action_fcurves(action, rig))
    assert (bpy.context.scene.frame_start, bpy.context.scene.frame_end) == (1, frames)


@pytest.mark.parametrize("average", [FEMALE_SET, FEMALE_FINE_SET], indirect=True)
def test_a_posed_obj_holds_the_posed_pieces(average, tmp_path):
    from ellimann_addon.core.formats.obj import write_obj

    path = tmp_path / "t.obj"
    write_obj(average, path, pose=clamped_motion("t_pose", average.joints)[0][0])
    vertices = np.array(
        [[float(v) for v in line.split()[1:4]] for line in path.read_text().splitlines() if line.startswith("v ")]
    )
    width = vertices[:, 0].max() - vertices[:, 0].min()  # OBJ is Y-up; x is still the body's left
    assert width > 1.2 * (average.center[:, 0].max() - average.center[:, 0].min())  # arms out: wider than at rest


@pytest.mark.parametrize(
    "change, message",
    [
        ({"pose": "dance"}, "unknown pose 'dance'"),
        ({"joints": None}, "has no joints"),
        ({"path": "x.fbx"}, "is not a .blend or .glb file"),
    ],
)
def test_refused_before_anything_is_written(average, tmp_path, change, message):
    pose = change.get("pose", "sit")
    mannequin = average.copy(joints=None) if "joints" in change else average
    with pytest.raises(ElliMannError, match=message):
        write_mannequin(mannequin, [tmp_path / "x.glb", tmp_path / change.get("path", "x.blend")], pose=pose)
    assert not list(tmp_path.iterdir())
