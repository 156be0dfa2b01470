"""The test helpers themselves: a state snapshot must notice real changes and ignore float noise."""

import bpy

from devkit.blender_scene import parts, state


def test_state_notices_moves_and_field_changes_but_not_reevaluation(toy_collection):
    before = state()
    bpy.context.view_layer.update()
    assert state() == before
    obj = parts(toy_collection)["1.a Head"]
    obj.location.x += 1e-4
    bpy.context.view_layer.update()
    assert state() != before
    obj.location.x -= 1e-4
    bpy.context.view_layer.update()
    assert state() == before
    obj.ellimann.region = "skull"
    assert state() != before


def test_state_notices_new_mesh_data_and_frame_changes(toy_collection):
    before = state()
    bpy.context.scene.frame_current = 7
    assert state() != before
    bpy.context.scene.frame_current = before["frames"][2]
    assert state() == before
    mesh = bpy.data.meshes["ElliMann Unit Sphere"]
    mesh.vertices.add(1)
    assert state() != before
