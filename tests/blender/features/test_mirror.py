"""Mirroring selected ellipsoids and whole sides across x = 0."""

import bpy
import numpy as np
import pytest

from devkit.blender_scene import parts, select, state
from ellimann_addon.blender.bridge.convert import collection_to_mannequin, ellipsoid_frame
from ellimann_addon.core.geometry.frames import is_rotation
from ellimann_addon.core.mannequin.clean import asymmetry


def symmetric(collection):
    # asymmetry() is the square root of shape-matrix differences: single-precision matrices give ~1e-4.
    return asymmetry(collection_to_mannequin(collection)) < 5e-4


def remove(*objects):
    for obj in objects:
        bpy.data.objects.remove(obj)


def test_mirror_selected_creates_the_missing_twin_as_a_right_handed_mirror(toy_collection):
    objs = parts(toy_collection)
    remove(objs["6.a Thigh.R"])
    select(objs["6.a Thigh.L"])
    assert bpy.ops.ellimann.mirror_ellipsoids() == {"FINISHED"}
    twin = parts(toy_collection)["6.a Thigh.R"]
    assert twin.ellimann.side == "R" and twin.ellimann.partner == "6.b Shin.R"
    assert twin.ellimann.depends == {"He", "Hi"} and twin.ellimann.region == "legs"
    r, c, d = ellipsoid_frame(twin)
    r0, c0, d0 = ellipsoid_frame(objs["6.a Thigh.L"])
    assert is_rotation(r) and np.allclose(c, c0 * (-1, 1, 1)) and np.allclose(d, d0)
    assert symmetric(toy_collection)


def test_existing_twin_is_only_replaced_when_asked(toy_collection):
    objs = parts(toy_collection)
    objs["5.a Arm.R"].location.z += 0.2
    bpy.context.view_layer.update()
    select(objs["5.a Arm.L"])
    before = state()
    with pytest.raises(RuntimeError, match="'5.a Arm.R' exists in 'toy': left alone"):
        bpy.ops.ellimann.mirror_ellipsoids()
    assert state() == before
    assert bpy.ops.ellimann.mirror_ellipsoids(replace=True) == {"FINISHED"}
    assert objs["5.a Arm.R"].name in bpy.data.objects  # moved in place, not deleted and recreated
    assert symmetric(toy_collection)


def test_mirror_selected_refuses_central_and_both_sides_and_changes_nothing(toy_collection):
    objs = parts(toy_collection)
    before = state()
    select(objs["1.a Head"], objs["5.a Arm.L"], objs["5.a Arm.R"])
    with pytest.raises(RuntimeError, match="one side only"):
        bpy.ops.ellimann.mirror_ellipsoids(replace=True)
    assert state() == before
    select()
    assert not bpy.ops.ellimann.mirror_ellipsoids.poll()


def test_mirror_side_builds_the_whole_other_side(toy_collection):
    objs = parts(toy_collection)
    right = [o for name, o in objs.items() if name.endswith(".R")]
    remove(*right)
    objs["4.a Trapezius.L"].location.x += 0.03
    bpy.context.view_layer.update()
    assert bpy.ops.ellimann.mirror_side(source="L") == {"FINISHED"}
    mannequin = collection_to_mannequin(toy_collection)
    assert len(mannequin) == 12 and symmetric(toy_collection)


def test_mirror_side_left_to_right_replaces_asymmetric_twins_when_asked(toy_collection):
    objs = parts(toy_collection)
    objs["6.b Shin.R"].rotation_euler.x += 0.3
    bpy.context.view_layer.update()
    assert asymmetry(collection_to_mannequin(toy_collection)) > 0.01
    with pytest.raises(RuntimeError, match="Nothing mirrored"):
        bpy.ops.ellimann.mirror_side(source="L")
    assert bpy.ops.ellimann.mirror_side(source="L", replace=True) == {"FINISHED"}
    assert symmetric(toy_collection)


def test_mirror_refuses_a_negative_scale_source(toy_collection):
    objs = parts(toy_collection)
    remove(objs["6.a Thigh.R"])
    objs["6.a Thigh.L"].scale.x *= -1
    bpy.context.view_layer.update()
    select(objs["6.a Thigh.L"])
    before = state()
    with pytest.raises(RuntimeError, match="Fix these ellipsoids first"):
        bpy.ops.ellimann.mirror_ellipsoids()
    assert state() == before
