"""Validation by part name, and the repair of applied scale, negative scale and shear."""

import bpy
import numpy as np
import pytest

from devkit.blender_scene import parts, select, state
from ellimann_addon.blender.bridge.checks import frame_issue
from ellimann_addon.blender.bridge.convert import UNIT_SPHERE_NAME, ellipsoid_frame, is_unit_sphere, mesh_vertices
from ellimann_addon.core.geometry.ellipsoid import shape_matrix
from ellimann_addon.core.geometry.frames import is_rotation


def world_set(obj):
    """(centre, shape matrix) of the point set the object shows: its mesh's transform times matrix_world."""
    matrix = np.array(obj.matrix_world)
    vertices = mesh_vertices(obj.data)
    if not is_unit_sphere(obj.data):
        from ellimann_addon.core.constants import UNIT_SPHERE_LEVEL
        from ellimann_addon.core.fitting.point_fit import fit_affine
        from ellimann_addon.core.geometry.mesh import icosphere

        matrix = matrix @ fit_affine(icosphere(UNIT_SPHERE_LEVEL)[0], vertices)[0]
    linear = matrix[:3, :3]
    return matrix[:3, 3], linear @ linear.T


def assert_same_set(before, obj):
    center, shape = before
    rotation, c, semi = ellipsoid_frame(obj)
    assert is_rotation(rotation) and np.allclose(c, center, atol=1e-6)
    assert np.allclose(shape_matrix(rotation, semi), shape, atol=1e-7)


def test_validate_passes_a_good_mannequin(toy_collection, capfd):
    assert bpy.ops.ellimann.validate_mannequin() == {"FINISHED"}
    assert "'toy' is a valid mannequin (12 ellipsoids)" in capfd.readouterr().out


def test_validate_reports_every_problem_by_part_name(toy_collection, capfd):
    objs = parts(toy_collection)
    objs["1.a Head"].scale.x *= -1
    objs["5.a Arm.R"].ellimann.part_name = "5.a Arm.X"
    objs["6.b Shin.L"].ellimann.partner = ""
    bpy.context.view_layer.update()
    before = state()
    with pytest.raises(RuntimeError, match="'toy' has 7 problems: '1.a Head' rotation"):
        bpy.ops.ellimann.validate_mannequin()
    out = capfd.readouterr().out
    assert "'1.a Head' rotation: rotation is left-handed" in out
    assert "'5.a Arm.X' name: must look like" in out
    assert "'5.a Arm.L' side: has no mirror twin '5.a Arm.R'" in out
    assert "'6.a Thigh.L' partner: '6.b Shin.L' does not name it back as partner" in out
    assert "'5.a Arm.X' side: is 'R' but the name's suffix says 'C'" in out
    assert state() == before


def test_fix_negative_scale_flips_that_axis_back(toy_collection):
    obj = parts(toy_collection)["6.a Thigh.L"]
    rotation, _, semi = ellipsoid_frame(obj)
    obj.scale.y *= -1
    bpy.context.view_layer.update()
    assert frame_issue(obj).kind == "negative"
    before = world_set(obj)
    select(obj)
    assert bpy.ops.ellimann.fix_frames() == {"FINISHED"}
    assert frame_issue(obj) is None
    assert_same_set(before, obj)
    fixed_rotation, _, fixed_semi = ellipsoid_frame(obj)
    assert np.allclose(fixed_rotation, rotation, atol=1e-6) and np.allclose(fixed_semi, semi)


def test_fix_shear_clears_the_parent_and_keeps_the_shape(toy_collection, capfd):
    obj = parts(toy_collection)["3.a Pelvis"]
    parent = bpy.data.objects.new("Rig", None)
    bpy.context.scene.collection.objects.link(parent)
    parent.scale = (1.0, 1.6, 0.8)
    obj.parent = parent
    obj.rotation_euler = (0.4, 0.2, 0.3)
    bpy.context.view_layer.update()
    assert frame_issue(obj).kind == "shear"
    before = world_set(obj)
    select(obj)
    assert bpy.ops.ellimann.fix_frames() == {"FINISHED"}
    assert obj.parent is None and "Cleared the parent of 3.a Pelvis" in capfd.readouterr().out
    assert_same_set(before, obj)
    assert "Rig" in bpy.data.objects


def test_fix_applied_scale_restores_the_shared_unit_sphere(toy_collection):
    obj = parts(toy_collection)["2.a Chest"]
    select(obj)
    bpy.ops.object.transform_apply(location=False, rotation=True, scale=True, isolate_users=True)
    assert obj.data.name != UNIT_SPHERE_NAME and frame_issue(obj).kind == "mesh"
    with pytest.raises(RuntimeError, match="not a unit sphere"):
        bpy.ops.ellimann.measure_mannequin()
    before = world_set(obj)
    assert bpy.ops.ellimann.fix_frames() == {"FINISHED"}
    assert obj.data.name == UNIT_SPHERE_NAME
    assert_same_set(before, obj)
    assert bpy.ops.ellimann.validate_mannequin() == {"FINISHED"}


def test_fix_refuses_edited_meshes_zero_scale_and_valid_frames(toy_collection, capfd):
    objs = parts(toy_collection)
    select(objs["1.a Head"])
    with pytest.raises(RuntimeError, match="Nothing to fix"):
        bpy.ops.ellimann.fix_frames()
    bpy.ops.object.transform_apply(location=False, rotation=False, scale=True, isolate_users=True)
    objs["1.a Head"].data.vertices[0].co.x += 0.05
    objs["5.a Arm.L"].scale.z = 0.0
    bpy.context.view_layer.update()
    select(objs["1.a Head"], objs["5.a Arm.L"])
    before = state()
    with pytest.raises(RuntimeError, match="No ellipsoid could be repaired"):
        bpy.ops.ellimann.fix_frames()
    out = capfd.readouterr().out
    assert "'1.a Head': mesh was edited beyond a scale or rotation" in out
    assert "'5.a Arm.L': scale has a zero axis" in out
    assert state() == before
