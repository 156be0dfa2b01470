import bpy
import numpy as np
import pytest

from ellimann_addon.blender.bridge import convert
from ellimann_addon.core.errors import MannequinError


def test_collection_round_trip_is_lossless(toy):
    toy.measurements = {"He": 160.0, "Sh": 40.0, "Br": 90.0, "Wa": 70.0, "Hi": 95.0}
    collection = convert.mannequin_to_collection(toy)
    assert collection.ellimann.is_mannequin and len(collection.objects) == len(toy)
    back = convert.collection_to_mannequin(collection)
    back = back.reordered(toy.topology)
    assert back.topology == toy.topology and back.role == toy.role
    assert back.measurements == toy.measurements
    # matrix_world is single precision in Blender
    assert np.allclose(back.rotation, toy.rotation, atol=1e-6)
    assert np.allclose(back.center, toy.center, atol=1e-6)
    assert np.allclose(back.semi_axes, toy.semi_axes, rtol=1e-6)
    assert back.measure() == pytest.approx(toy.measure(), rel=1e-5)


def test_objects_share_one_unit_sphere_and_carry_their_frame(toy):
    collection = convert.mannequin_to_collection(toy)
    meshes = {o.data for o in collection.objects}
    assert meshes == {bpy.data.meshes[convert.UNIT_SPHERE_NAME]}
    obj = next(o for o in collection.objects if o.ellimann.part_name == "6.a Thigh.L")
    i = toy.topology.index["6.a Thigh.L"]
    assert np.allclose(np.array(obj.scale), toy.semi_axes[i], rtol=1e-6)
    assert np.allclose(np.array(obj.location), toy.center[i], atol=1e-6)
    assert obj.ellimann.partner == "6.b Shin.L" and obj.ellimann.depends == {"He", "Hi"}


def test_second_mannequin_goes_into_a_new_collection(toy):
    first = convert.mannequin_to_collection(toy, name="Body")
    second = convert.mannequin_to_collection(toy, name="Body")
    assert first != second and first.name == "Body" and second.name != "Body"
    assert len(first.objects) == len(second.objects) == len(toy)
    names = [convert.collection_to_mannequin(c).topology.names for c in (first, second)]
    assert names[0] == names[1]


def test_negative_scale_and_shear_are_reported_by_part_name(toy):
    collection = convert.mannequin_to_collection(toy)
    objs = {o.ellimann.part_name: o for o in collection.objects}
    objs["1.a Head"].scale[0] *= -1
    parent = bpy.data.objects.new("Parent", None)
    bpy.context.scene.collection.objects.link(parent)
    parent.scale = (1.0, 2.0, 1.0)
    parent.rotation_euler = (0.3, 0.2, 0.1)
    bpy.context.view_layer.update()
    objs["3.a Pelvis"].parent = parent
    objs["3.a Pelvis"].rotation_euler = (0.4, 0.0, 0.3)
    bpy.context.view_layer.update()
    with pytest.raises(MannequinError) as info:
        convert.collection_to_mannequin(collection)
    text = [str(p) for p in info.value.problems]
    assert any(t.startswith("'1.a Head' rotation") and "left-handed" in t for t in text)
    assert any(t.startswith("'3.a Pelvis' rotation") and "sheared" in t for t in text)


def test_update_geometry_moves_objects_in_place(toy):
    collection = convert.mannequin_to_collection(toy)
    moved = toy.copy(center=toy.center + (0.0, 0.0, 0.1))
    convert.update_collection_geometry(collection, moved)
    back = convert.collection_to_mannequin(collection).reordered(toy.topology)
    assert np.allclose(back.center, moved.center, atol=1e-6)
    assert len(bpy.data.objects) == len(toy)


def test_joints_go_into_the_collection_and_back():
    from ellimann_addon.core.mannequin.model import Mannequin
    from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

    average = Mannequin.load(REFERENCE_FOLDER / "average.json")
    back = convert.collection_to_mannequin(convert.mannequin_to_collection(average))
    assert np.abs(back.joints - average.joints).max() < 1e-6  # Blender keeps 32-bit floats
    without = convert.collection_to_mannequin(convert.mannequin_to_collection(average.copy(joints=None)))
    assert without.joints is None


def test_empty_collection_is_refused():
    collection = convert.new_collection("Nothing")
    with pytest.raises(MannequinError, match="holds no ElliMann ellipsoids"):
        convert.collection_to_mannequin(collection)
