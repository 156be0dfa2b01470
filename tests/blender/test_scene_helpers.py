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
