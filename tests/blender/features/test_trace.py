"""New mannequin, add an ellipsoid at the cursor, fit one to selected vertices."""

import bpy
import numpy as np
import pytest

from devkit.blender_scene import edit_with_selection, parts, reference_mesh, state
from devkit.toy import rotation_from_vector
from ellimann_addon.blender.bridge.convert import collection_to_mannequin, ellipsoid_frame
from ellimann_addon.blender.features.trace.operators import FIT_MODE_ITEMS, next_part_name
from ellimann_addon.core.fitting.point_fit import FIT_MODES, fit_ellipsoid
from ellimann_addon.core.geometry.frames import is_rotation


def test_fit_mode_items_are_the_core_modes():
    assert tuple(item[0] for item in FIT_MODE_ITEMS) == FIT_MODES


def test_next_part_name_numbers_on_and_picks_the_side_from_the_position():
    assert next_part_name({}, 0.0, 0.1) == "1.a Ellipsoid"
    assert next_part_name({"2.a Chest": 0, "10.b Shin.L": 0, "junk": 0}, 0.3, 0.1) == "11.a Ellipsoid.L"
    assert next_part_name({}, -0.3, 0.1) == "1.a Ellipsoid.R"
    assert next_part_name({}, 0.05, 0.1) == "1.a Ellipsoid"  # straddles x = 0: central


def test_new_mannequin_becomes_the_active_collection():
    assert bpy.ops.ellimann.new_mannequin(name="Traced", role="base") == {"FINISHED"}
    collection = bpy.data.collections["Traced"]
    assert collection.ellimann.is_mannequin and collection.ellimann.role == "base"
    assert bpy.context.view_layer.active_layer_collection.collection == collection


def test_add_ellipsoid_at_the_cursor_into_a_new_mannequin_then_the_same_one():
    bpy.context.scene.cursor.location = (0.2, -0.1, 1.3)
    assert bpy.ops.ellimann.add_ellipsoid(semi_axes=(0.1, 0.05, 0.2)) == {"FINISHED"}
    obj = bpy.context.active_object
    collection = obj.users_collection[0]
    assert collection.ellimann.is_mannequin and collection.ellimann.role == "base"
    assert obj.ellimann.part_name == "1.a Ellipsoid.L" and obj.ellimann.side == "L" and obj.select_get()
    rotation, center, semi_axes = ellipsoid_frame(obj)
    assert np.allclose(center, (0.2, -0.1, 1.3)) and np.allclose(semi_axes, (0.1, 0.05, 0.2))
    assert np.allclose(rotation, np.eye(3))
    bpy.context.scene.cursor.location = (0.0, 0.0, 1.0)
    assert bpy.ops.ellimann.add_ellipsoid(part_name="3.a Chest") == {"FINISHED"}
    assert sorted(parts(collection)) == ["1.a Ellipsoid.L", "3.a Chest"]
    assert len([c for c in bpy.data.collections if c.ellimann.is_mannequin]) == 1


def test_add_ellipsoid_refuses_bad_or_taken_names_and_changes_nothing(toy_collection):
    before = state()
    with pytest.raises(RuntimeError, match="must look like '10.a Trapezius.L'"):
        bpy.ops.ellimann.add_ellipsoid(part_name="Head")
    with pytest.raises(RuntimeError, match="already has a part '1.a Head'"):
        bpy.ops.ellimann.add_ellipsoid(part_name="1.a Head")
    assert state() == before


def test_add_ellipsoid_without_mannequin_and_bad_name_creates_no_collection():
    before = state()
    with pytest.raises(RuntimeError, match="must look like"):
        bpy.ops.ellimann.add_ellipsoid(part_name="no number")
    assert state() == before and not bpy.data.collections


@pytest.mark.parametrize("mode", FIT_MODES)
def test_fit_recovers_the_selected_ellipsoid_in_world_coordinates(mode):
    rotation = rotation_from_vector((0.3, -0.2, 0.5))
    obj = reference_mesh(rotation, (0.25, 0.05, 0.9), np.array((0.06, 0.08, 0.2)))
    edit_with_selection(obj, slice(None))
    assert bpy.ops.ellimann.fit_ellipsoid(mode=mode) == {"FINISHED"}
    assert bpy.context.mode == "EDIT_MESH" and bpy.context.active_object == obj
    fitted = next(o for o in bpy.data.objects if o.ellimann.is_part)
    r, c, d = ellipsoid_frame(fitted)
    assert is_rotation(r) and np.linalg.det(r) > 0
    assert np.allclose(c, (0.25, 0.05, 0.9), atol=1e-6)
    assert np.allclose(np.sort(d), (0.06, 0.08, 0.2), rtol=1e-5)
    assert fitted.ellimann.part_name == "1.a Ellipsoid.L"  # wholly on the body's left (+X)


def test_fit_uses_only_the_selected_vertices_and_agrees_with_the_core():
    obj = reference_mesh(np.eye(3), (0.0, 0.0, 1.0), np.array((0.3, 0.2, 0.1)))
    world = np.array([v.co for v in obj.data.vertices]) + (0.0, 0.0, 1.0)
    chosen = np.nonzero(world[:, 0] > 0.05)[0]
    edit_with_selection(obj, chosen)
    assert bpy.ops.ellimann.fit_ellipsoid(mode="moments", part_name="4.a Half") == {"FINISHED"}
    fitted = parts(bpy.context.view_layer.active_layer_collection.collection)["4.a Half"]
    expected = fit_ellipsoid(world[chosen], "moments")
    got = ellipsoid_frame(fitted)
    for a, b in zip(got, expected):
        assert np.allclose(a, b, atol=1e-5)


def test_inscribed_fit_keeps_every_vertex_of_the_traced_mesh_outside():
    obj = reference_mesh(np.eye(3), (0.0, 0.0, 1.0), np.array((0.2, 0.2, 0.2)))
    local = np.array([v.co for v in obj.data.vertices])
    groove = (np.abs(local[:, 2]) < 0.05) & (local[:, 0] < -0.1)  # pressed in, and left unselected
    local[groove] *= 0.5
    obj.data.vertices.foreach_set("co", local.astype(np.float32).ravel())
    edit_with_selection(obj, np.nonzero(~groove)[0])
    assert bpy.ops.ellimann.fit_ellipsoid(mode="inscribed", part_name="1.a Body") == {"FINISHED"}
    collection = bpy.context.view_layer.active_layer_collection.collection
    rotation, center, semi = ellipsoid_frame(parts(collection)["1.a Body"])
    world = local + (0.0, 0.0, 1.0)
    assert np.sum(((world - center) @ rotation / semi) ** 2, axis=1).min() >= 1 - 1e-5
    assert np.sum(((world[groove] - center) @ rotation / semi) ** 2, axis=1).min() == pytest.approx(1, abs=1e-5)


def test_fit_goes_into_the_active_mannequin(toy_collection):
    obj = reference_mesh(np.eye(3), (0.0, 0.0, 1.0), np.array((0.1, 0.1, 0.1)))
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    from ellimann_addon.blender.bridge.selection import set_active_collection

    set_active_collection(bpy.context, toy_collection)
    edit_with_selection(obj, slice(None))
    assert bpy.ops.ellimann.fit_ellipsoid() == {"FINISHED"}
    assert "7.a Ellipsoid" in parts(toy_collection)  # the toy's parts are numbered 1 to 6
    bpy.ops.object.mode_set(mode="OBJECT")
    assert len(collection_to_mannequin(toy_collection, check=False)) == 13


def test_fit_refuses_too_few_or_flat_selections_and_changes_nothing():
    obj = reference_mesh(np.eye(3), (0.0, 0.0, 1.0), np.array((0.1, 0.1, 0.1)))
    edit_with_selection(obj, [0, 1, 2])
    before = state()
    with pytest.raises(RuntimeError, match="Select at least 4 vertices"):
        bpy.ops.ellimann.fit_ellipsoid()
    bpy.ops.object.mode_set(mode="OBJECT")
    ring = np.nonzero(np.abs(np.array([v.co.z for v in obj.data.vertices])) < 1e-6)[0]
    assert len(ring) >= 4
    edit_with_selection(obj, ring)
    with pytest.raises(RuntimeError, match="coplanar"):
        bpy.ops.ellimann.fit_ellipsoid()
    bpy.ops.object.mode_set(mode="OBJECT")
    assert state() == before


def test_fit_needs_edit_mode_and_add_needs_object_mode():
    assert not bpy.ops.ellimann.fit_ellipsoid.poll()
    assert bpy.ops.ellimann.add_ellipsoid.poll()
    obj = reference_mesh(np.eye(3), (0.0, 0.0, 1.0), np.array((0.1, 0.1, 0.1)))
    edit_with_selection(obj, slice(None))
    assert bpy.ops.ellimann.fit_ellipsoid.poll() and not bpy.ops.ellimann.add_ellipsoid.poll()
