"""The skin in Blender: Build Skin on any mannequin (a child object bound by an Armature modifier, rebuilt in place,
nothing of the user's touched, refusals that change nothing), posed by Blender as the core poses it, written to .glb
(a skinned glTF with the walk, no validator error, posed where Blender shows it) and .blend (the pieces hidden beside
it as colliders), and the Synthesize panel's Skin option, live."""

import bpy
import numpy as np
import pytest

from devkit import gltf_skin, gltf_validator
from devkit.blender_scene import parts, state
from ellimann_addon.blender.bridge.built import built_objects
from ellimann_addon.blender.bridge.convert import collection_to_mannequin, mannequin_to_collection, rig_object
from ellimann_addon.blender.bridge.skin import is_stale_skin, read_skin, skin_object, skin_vertices
from ellimann_addon.blender.features.skin import live as skin_live
from ellimann_addon.blender.services.files import write_mannequin
from ellimann_addon.blender.services.posing import write_posed
from ellimann_addon.blender.services.rig import MODIFIER_NAME, apply_pose, build_rig
from ellimann_addon.blender.services.skin import COLLIDER_NAME
from ellimann_addon.core.geometry.mesh import is_closed_manifold
from ellimann_addon.core.mannequin.skeleton import JOINT_NAMES
from ellimann_addon.core.mannequin.skin_record import SkinSettings
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.pose.motion import clamped_motion
from ellimann_addon.core.skin.exact import MESH_TOLERANCE_CM
from ellimann_addon.core.skin.measure import mesh_measurements
from ellimann_addon.core.skin.surface import build_skin
from ellimann_addon.core.synthesis.shipped import named_reference_set

Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # glTF (x, y, z) -> Blender


@pytest.fixture(scope="module")
def average():
    return named_reference_set("female").mannequins[4]


@pytest.fixture(scope="module")
def preview_skin(average):
    skin = build_skin(average, SkinSettings.at_level("preview"))
    skin.bones()
    return skin


def rigged(mannequin, rig=True):
    """The mannequin as a collection (rigged), its first ellipsoid active."""
    collection = mannequin_to_collection(mannequin)
    if rig:
        build_rig(collection, mannequin)
    bpy.context.view_layer.objects.active = parts(collection)["1.a Cranium"]
    return collection


def evaluated_world(obj):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    evaluated.to_mesh_clear()
    matrix = np.array(obj.matrix_world)
    return co.reshape(-1, 3).astype(float) @ matrix[:3, :3].T + matrix[:3, 3]


def faces_of(obj):
    mesh = obj.data
    mesh.calc_loop_triangles()
    faces = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", faces)
    return faces.reshape(-1, 3)


def test_build_skin_makes_a_closed_skin_in_a_child_collection_bound_to_the_armature(average):
    collection = rigged(average)
    assert bpy.ops.ellimann.build_skin(level="PREVIEW") == {"FINISHED"}
    obj = skin_object(collection)
    assert obj.ellimann.kind == "SKIN" and obj.users_collection[0] in list(collection.children)
    rig = rig_object(collection)
    assert obj.parent == rig and obj.modifiers[0].type == "ARMATURE" and obj.modifiers[0].object == rig
    assert {g.name for g in obj.vertex_groups} <= set(JOINT_NAMES) and len(obj.vertex_groups) >= 20
    assert is_closed_manifold(faces_of(obj))
    skin = read_skin(obj, collection_to_mannequin(collection))
    assert skin is not None and skin.settings == SkinSettings.at_level("preview")
    assert not is_stale_skin(obj, collection_to_mannequin(collection))
    assert np.allclose(evaluated_world(obj), skin.vertices, atol=1e-6)  # at rest, the armature moves nothing


def test_blender_poses_the_skin_as_the_core_does(average):
    collection = rigged(average)
    assert bpy.ops.ellimann.build_skin(level="PREVIEW") == {"FINISHED"}
    obj = skin_object(collection)
    skin = skin_live.remembered(obj)
    for name in ("sit", "t_pose"):
        pose = clamped_motion(name, average.joints)[0][0]
        apply_pose(rig_object(collection), pose)
        bpy.context.view_layer.update()
        # vertex groups hold weights to 1/1024 (services.rig.WEIGHT_STEPS); the modifier normalises them
        assert np.abs(evaluated_world(obj) - skin.posed(pose)).max() < 1e-3


def test_build_skin_again_rebuilds_in_place_and_keeps_the_users_things(average):
    collection = rigged(average)
    assert bpy.ops.ellimann.build_skin(level="PREVIEW") == {"FINISHED"}
    obj = skin_object(collection)
    obj.name, mesh_name = "My Body", obj.data.name
    material = bpy.data.materials.new("Mine")
    obj.data.materials.append(material)
    obj.modifiers.new("Smooth", "SUBSURF")
    obj.vertex_groups.new(name="Mine")
    mine = bpy.data.objects.new("Beside", None)
    collection.children[0].objects.link(mine)  # the user's own object in the Skin collection
    parts(collection)["5.a Thigh.L"].location.x += 0.01
    bpy.context.view_layer.update()
    assert is_stale_skin(obj, collection_to_mannequin(collection))
    before = len(obj.data.vertices)
    assert bpy.ops.ellimann.build_skin(level="PREVIEW") == {"FINISHED"}
    assert skin_object(collection) == obj and obj.name == "My Body" and obj.data.name == mesh_name
    assert list(obj.data.materials) == [material] and "Mine" in obj.vertex_groups
    assert [m.name for m in obj.modifiers] == [MODIFIER_NAME, "Smooth"]  # the armature deforms first
    assert mine.name in collection.children[0].objects
    assert not is_stale_skin(obj, collection_to_mannequin(collection)) and len(obj.data.vertices) != before


def test_a_skin_without_an_armature_is_weighted_and_add_armature_binds_it(average):
    collection = rigged(average, rig=False)
    assert bpy.ops.ellimann.build_skin(level="PREVIEW") == {"FINISHED"}
    obj = skin_object(collection)
    assert obj.parent is None and not obj.modifiers and len(obj.vertex_groups) >= 20
    assert bpy.ops.ellimann.add_armature() == {"FINISHED"}
    assert obj.modifiers[0].object == rig_object(collection) and len(obj.vertex_groups) >= 20


def test_a_mannequin_without_joints_gets_a_skin_that_does_not_pose(average):
    collection = rigged(average.copy(joints=None), rig=False)
    assert bpy.ops.ellimann.build_skin(level="PREVIEW") == {"FINISHED"}
    obj = skin_object(collection)
    assert not obj.vertex_groups and not obj.modifiers


@pytest.mark.parametrize(
    "values, message",
    [
        ({"voxel": 0.5}, "skin_voxel: must be a number from 1 to 40, got 0.5"),
        ({"voxel": 30.0}, "too thin for 30 mm voxels"),
    ],
)
def test_build_skin_refuses_bad_settings_in_one_line_and_changes_nothing(average, values, message):
    rigged(average)
    before = state()
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.ellimann.build_skin(level="PREVIEW", **values)
    assert state() == before


def test_build_skin_needs_a_mannequin():
    assert not bpy.ops.ellimann.build_skin.poll()


def test_a_glb_with_a_skin_is_a_valid_skinned_gltf_with_the_walk(average, preview_skin, tmp_path):
    path = tmp_path / "walk.glb"
    write_posed(average, clamped_motion("walk", average.joints)[0], [path], cushions=True, skin=preview_skin)
    issues = gltf_validator.validate(path)
    assert issues["numErrors"] == 0, gltf_validator.errors(issues)
    doc, binary = gltf_skin.read_glb(path)
    assert len(doc["animations"]) == 1 and len(doc["skins"]) == 1
    obj = skin_object(next(c for c in bpy.data.collections if c.ellimann.is_mannequin))
    node = next(n for n in doc["nodes"] if n.get("name") == obj.name)
    assert node["extras"]["ellimann"] == {"kind": "SKIN", "skin": preview_skin.settings.to_dict()}
    primitive = doc["meshes"][node["mesh"]]["primitives"][0]
    weights = gltf_skin.accessor(doc, binary, primitive["attributes"]["WEIGHTS_0"])
    assert np.allclose(weights.sum(axis=1), 1.0, atol=1e-3) and (weights[:, 1] > 0.0).any()  # blended, not rigid
    # the pieces are there too, inside the skin (colliders for an engine)
    # (the armature's node carries the mannequin's extras, without a kind)
    kinds = [n["extras"]["ellimann"].get("kind") for n in doc["nodes"] if "ellimann" in n.get("extras", {})]
    assert kinds.count("SKIN") == 1 and "CUSHION" in kinds and "ELLIPSOID" in kinds


def test_a_posed_glb_shows_the_skin_where_blender_and_the_core_pose_it(average, preview_skin, tmp_path):
    path = tmp_path / "sit.glb"
    pose = clamped_motion("sit", average.joints)[0][0]
    write_posed(average, [pose], [path], skin=preview_skin)
    doc, binary = gltf_skin.read_glb(path)
    obj = skin_object(next(c for c in bpy.data.collections if c.ellimann.is_mannequin))
    shown = gltf_skin.skinned_positions(doc, binary, obj.name) @ Y_UP_TO_Z_UP.T
    assert np.abs(shown - evaluated_world(obj)).max() < 1e-5
    assert np.abs(shown - preview_skin.posed(pose)).max() < 1e-3  # weights to 1/1024 in the file


def test_a_blend_with_a_skin_keeps_the_pieces_hidden_as_colliders(average, preview_skin, tmp_path):
    path = tmp_path / "rest.blend"
    write_mannequin(average, [path, tmp_path / "rest.glb"], skin=preview_skin)
    bpy.ops.wm.open_mainfile(filepath=str(path))
    collection = next(c for c in bpy.data.collections if c.ellimann.is_mannequin)
    obj = skin_object(collection)
    assert obj.visible_get() and not obj.hide_render and obj.modifiers[0].object == rig_object(collection)
    pieces = [o for o in collection.objects if o.ellimann.is_part and o.ellimann.kind == "ELLIPSOID"]
    assert len(pieces) == len(average.topology)
    assert all(o.hide_get() and o.hide_render and o.modifiers.get(COLLIDER_NAME) for o in pieces)
    assert all(o.modifiers[0].type == "ARMATURE" for o in pieces)  # posed with the skin, then colliding
    assert gltf_validator.validate(tmp_path / "rest.glb")["numErrors"] == 0


@pytest.fixture
def props():
    props = bpy.context.scene.ellimann_synthesis
    props.reference_set, props.mode, props.live, props.skin = "FEMALE", "EXACT", False, True
    props.skin_kind, props.skin_level = "PIECES", "PREVIEW"
    for key, value in zip(MEASUREMENTS, (159.0, 43.0, 117.0, 104.0, 117.0)):
        setattr(props, key.lower(), value)
    return props


def fire_skin_settle():
    assert bpy.app.timers.is_registered(skin_live._settle_timer)
    bpy.app.timers.unregister(skin_live._settle_timer)
    assert skin_live._settle_timer() is None


def test_synthesize_with_skin_and_live_the_skin_follows_the_pieces_then_is_made_again(props):
    assert bpy.ops.ellimann.synthesize_mannequin() == {"FINISHED"}
    target = props.target
    obj = skin_object(target)
    assert obj is not None and obj.modifiers[0].object == rig_object(target)
    made = skin_live.remembered(obj)
    props.live = True
    props.he = 165.0  # a live step: the skin moves with its pieces, no new surface
    moved = skin_live.remembered(obj)
    assert moved is made and len(obj.data.vertices) == len(made.vertices)
    following = made.following(collection_to_mannequin(target))
    assert np.abs(evaluated_world(obj) - following.vertices).max() < 1e-5
    assert evaluated_world(obj)[:, 2].max() > made.vertices[:, 2].max() + 0.03  # taller
    assert is_stale_skin(obj, collection_to_mannequin(target))
    fire_skin_settle()  # the fields are still: a new skin from the settled pieces, at the preview level
    assert skin_object(target) == obj and not is_stale_skin(obj, collection_to_mannequin(target))
    assert skin_live.remembered(obj) is not made and len(built_objects(target, "SKIN")) == 1
    props.live = False


def test_the_body_skin_is_the_panel_s_default_follows_a_live_step_by_the_bodies_blend_and_is_made_exact_once_still(
    props,
):
    """Skin kind Auto on a set with bodies: the body skin (the set's bodies' own topology), bound to the armature;
    a live step gives it the body model's blend for the new request at once, and the exact body skin once the fields
    are still."""
    from ellimann_addon.core.job.make import body_skin_maker
    from ellimann_addon.core.synthesis.shipped import named_reference_set

    props.skin_kind = "AUTO"
    assert bpy.ops.ellimann.synthesize_mannequin() == {"FINISHED"}
    target = props.target
    obj = skin_object(target)
    made = skin_live.remembered(obj)
    assert made.settings.kind == "body" and len(obj.data.vertices) == len(made.vertices) == 13348
    assert obj.modifiers[0].object == rig_object(target)
    asked = dict(zip(MEASUREMENTS, (159.0, 43.0, 117.0, 104.0, 117.0)))
    assert all(abs(made.measured[key] - wanted) <= MESH_TOLERANCE_CM for key, wanted in asked.items())
    props.live = True
    props.he = 165.0  # a live step: the bodies' blend for the new request, no correction yet
    blend, _ = body_skin_maker(named_reference_set("female")).interpolated({**asked, "He": 165.0})
    assert np.abs(skin_vertices(obj) - blend).max() < 1e-5
    fire_skin_settle()
    settled = skin_live.remembered(obj)
    assert settled is not made and settled.settings.kind == "body" and abs(settled.measured["He"] - 165.0) <= 0.1
    props.live = False


def test_synthesize_with_skin_in_exact_mode_makes_the_skin_measure_the_request(props):
    """The skin the user sees meets the five (the pieces under it measure less: the blend adds the rest), and the
    report says what the skin measures."""
    assert bpy.ops.ellimann.synthesize_mannequin() == {"FINISHED"}
    skin = skin_live.remembered(skin_object(props.target))
    asked = dict(zip(MEASUREMENTS, (159.0, 43.0, 117.0, 104.0, 117.0)))
    on_mesh = mesh_measurements(skin)
    assert all(abs(on_mesh[key] - wanted) <= MESH_TOLERANCE_CM for key, wanted in asked.items()), on_mesh
    pieces = collection_to_mannequin(props.target).measure()
    assert pieces["Hi"] < asked["Hi"] - MESH_TOLERANCE_CM
    assert np.allclose(skin.mannequin.center, collection_to_mannequin(props.target).center, atol=1e-6)


def test_ticking_skin_with_live_on_makes_one_when_the_fields_settle(props):
    props.skin = False
    assert bpy.ops.ellimann.synthesize_mannequin() == {"FINISHED"}
    target = props.target
    assert skin_object(target) is None
    props.live = True
    props.skin = True  # an update: the step has no skin to move; one is made once the fields are still
    fire_skin_settle()
    assert skin_object(target) is not None and skin_object(target).modifiers[0].object == rig_object(target)
    props.live = False
