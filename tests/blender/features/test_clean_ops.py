"""Relabel axes against a reference mannequin, symmetrize central ellipsoids, register to the world frame."""

import bpy
import numpy as np
import pytest

from devkit.blender_scene import parts, select, state
from devkit.toy import rotation_from_vector
from devkit.ui_recorder import draw_operator
from ellimann_addon.blender.bridge.convert import collection_to_mannequin, ellipsoid_frame, mannequin_to_collection
from ellimann_addon.blender.features.clean.operators import ELLIMANN_OT_relabel_axes
from ellimann_addon.core.geometry.ellipsoid import shape_matrix
from ellimann_addon.core.geometry.frames import axis_agreement
from ellimann_addon.core.mannequin.clean import register_to_world

# Turns that relabel axes: (x, y, z) -> (y, z, x) and a half turn about z.
CYCLE = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
HALF_TURN = np.diag([-1.0, -1.0, 1.0])


def scrambled(toy):
    """The toy with the same ellipsoids (as sets) but relabelled axes on every other part."""
    rotation, semi = toy.rotation.copy(), toy.semi_axes.copy()
    for i in range(0, len(toy), 2):
        q = CYCLE if i % 4 == 0 else HALF_TURN
        rotation[i] = rotation[i] @ q
        semi[i] = np.abs(q).T @ semi[i]
    return toy.copy(rotation=rotation, semi_axes=semi, name="scrambled")


def test_relabel_mannequin_restores_the_reference_labels_without_moving_anything(toy):
    reference = mannequin_to_collection(toy, name="Reference")
    target = mannequin_to_collection(scrambled(toy))
    select(next(iter(parts(target).values())))
    before = collection_to_mannequin(target).reordered(toy.topology)
    assert bpy.ops.ellimann.relabel_axes(reference=reference.name, scope="MANNEQUIN") == {"FINISHED"}
    after = collection_to_mannequin(target).reordered(toy.topology)
    assert np.allclose(axis_agreement(after.rotation, toy.rotation), 1.0, atol=1e-6)
    assert np.allclose(after.semi_axes, toy.semi_axes, rtol=1e-6)
    assert np.allclose(
        shape_matrix(after.rotation, after.semi_axes), shape_matrix(before.rotation, before.semi_axes), atol=1e-7
    )
    assert np.allclose(after.center, before.center)


def test_relabel_selected_touches_only_the_selection(toy):
    reference = mannequin_to_collection(toy, name="Reference")
    target = mannequin_to_collection(scrambled(toy))
    objs = parts(target)
    others = [o for n, o in objs.items() if n != "1.a Head"]
    untouched = np.array([o.matrix_world for o in others])
    select(objs["1.a Head"])
    assert bpy.ops.ellimann.relabel_axes(reference=reference.name, scope="SELECTED") == {"FINISHED"}
    r, _, _ = ellipsoid_frame(objs["1.a Head"])
    assert np.allclose(r, toy.rotation[toy.topology.index["1.a Head"]], atol=1e-6)
    # Blender re-derives matrix_world from location/rotation/scale: equal up to single precision.
    assert np.allclose(untouched, np.array([o.matrix_world for o in others]), atol=1e-7)


def test_relabel_refuses_a_missing_reference_and_parts_it_cannot_match(toy):
    target = mannequin_to_collection(scrambled(toy))
    select(parts(target)["1.a Head"])
    other = bpy.data.collections.new("Plain")
    before = state()
    with pytest.raises(RuntimeError, match="'Plain' is not one"):
        bpy.ops.ellimann.relabel_axes(reference="Plain")
    with pytest.raises(RuntimeError, match="'Nowhere' is not one"):
        bpy.ops.ellimann.relabel_axes(reference="Nowhere")
    unrelated = mannequin_to_collection(toy.copy(), name="Unrelated")
    for obj in unrelated.objects:
        obj.ellimann.part_name = "9.z Other " + obj.ellimann.part_name.split()[1]
    before = state()
    with pytest.raises(RuntimeError, match="None of the 12 ellipsoids has a part of the same name"):
        bpy.ops.ellimann.relabel_axes(reference="Unrelated", scope="MANNEQUIN")
    assert state() == before and other.name == "Plain"


def test_relabel_dialog_draws(toy_collection):
    recorder = draw_operator(ELLIMANN_OT_relabel_axes, reference="toy")
    assert recorder.props() == ["reference", "scope"]


def test_symmetrize_central_puts_central_ellipsoids_on_the_plane(toy):
    tilted = toy.copy()
    head = toy.topology.index["1.a Head"]
    tilted.center[head, 0] = 0.02
    tilted.rotation[head] = rotation_from_vector((0.1, 0.2, 0.3))
    collection = mannequin_to_collection(tilted)
    select(parts(collection)["1.a Head"])
    assert bpy.ops.ellimann.symmetrize_central(scope="MANNEQUIN") == {"FINISHED"}
    r, c, _ = ellipsoid_frame(parts(collection)["1.a Head"])
    assert abs(c[0]) < 1e-7
    assert np.isclose(np.abs(r[0]).max(), 1.0, atol=1e-6)  # one local axis along world X
    for name in ("5.a Arm.L", "6.a Thigh.R"):  # lateral parts are left alone
        i = toy.topology.index[name]
        assert np.allclose(ellipsoid_frame(parts(collection)[name])[1], tilted.center[i], atol=1e-6)


def test_symmetrize_refuses_a_selection_without_central_parts(toy_collection):
    select(parts(toy_collection)["5.a Arm.L"])
    before = state()
    with pytest.raises(RuntimeError, match="No central ellipsoids"):
        bpy.ops.ellimann.symmetrize_central(scope="SELECTED")
    assert state() == before


def test_register_moves_the_mannequin_and_its_cushions_like_the_core(toy):
    shifted = toy.copy(center=toy.center + (0.3, -0.2, 0.5))
    collection = mannequin_to_collection(shifted)
    select(parts(collection)["1.a Head"])
    bpy.ops.ellimann.build_cushions(subdivisions=2)
    cushion = collection.children[0].objects[0]
    cushion_before = np.array(cushion.matrix_world)
    assert bpy.ops.ellimann.register_mannequin() == {"FINISHED"}
    got = collection_to_mannequin(collection).reordered(toy.topology)
    expected = register_to_world(shifted)
    assert np.allclose(got.center, expected.center, atol=1e-6)
    offset = expected.center[0] - shifted.center[0]
    assert np.allclose(np.array(cushion.matrix_world)[:3, 3], cushion_before[:3, 3] + offset, atol=1e-6)


def test_register_refuses_a_mannequin_without_trapezius(toy):
    collection = mannequin_to_collection(toy)
    for obj in collection.objects:
        if "Trapezius" in obj.ellimann.part_name:
            obj.ellimann.part_name = obj.ellimann.part_name.replace("Trapezius", "Shoulder")
    select(parts(collection)["1.a Head"])
    before = state()
    with pytest.raises(RuntimeError, match="Cannot register 'toy'"):
        bpy.ops.ellimann.register_mannequin()
    assert state() == before
