"""One undo after a data-changing operator brings the file back to where it was; one redo brings the change back.

Headless Blender keeps an undo stack as the GUI does. ``ed.undo_push`` records the state before; an operator
called with ``undo=True`` (what a click in the GUI does) pushes its own step when it finishes, but only if its
``bl_options`` has ``'UNDO'``: without it there is no step to undo and ``ed.undo`` refuses to run.
"""

import bpy
import numpy as np

from devkit import synthetic
from devkit.blender_scene import edit_with_selection, parts, reference_mesh, select, state
from devkit.poses import make_apose_toy
from devkit.toy import rotation_from_vector
from ellimann_addon.blender.bridge.convert import mannequin_to_collection
from ellimann_addon.blender.services.scene import add_mannequin
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

CYCLE = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])  # relabels axes (x, y, z) -> (y, z, x)


def undo_redo(operator, **values):
    """Run ``operator`` as a GUI click does; assert it changed the file, that one undo restores the state before
    and one redo the state after. Returns the state after."""
    bpy.ops.ed.undo_push(message="Before")
    before = state()
    assert operator("EXEC_DEFAULT", True, **values) == {"FINISHED"}
    after = state()
    assert after != before
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert state() == before
    assert bpy.ops.ed.redo() == {"FINISHED"}
    assert state() == after
    return after


def test_undo_needs_the_operators_own_step():
    """The check above can fail: an operator run without its undo step leaves nothing to undo to."""
    bpy.ops.ed.undo_push(message="Before")
    assert bpy.ops.ellimann.new_mannequin(name="Traced") == {"FINISHED"}  # a script call pushes no step
    assert not bpy.ops.ed.undo.poll()


def test_new_mannequin():
    after = undo_redo(bpy.ops.ellimann.new_mannequin, name="Traced")
    assert after["active_collection"] == "Traced"


def test_add_ellipsoid(toy_collection):
    bpy.context.scene.cursor.location = (0.0, 0.0, 1.0)
    after = undo_redo(bpy.ops.ellimann.add_ellipsoid, part_name="9.a Extra")
    assert len(after["objects"]) == 13


def test_fit_ellipsoid_in_edit_mode():
    obj = reference_mesh(np.eye(3), (0.0, 0.0, 1.0), np.array((0.1, 0.2, 0.3)))
    edit_with_selection(obj, slice(None))
    after = undo_redo(bpy.ops.ellimann.fit_ellipsoid, mode="moments")
    assert bpy.context.mode == "EDIT_MESH" and sorted(after["objects"]) == ["1.a Ellipsoid", "Reference"]


def test_mirror_selected(toy_collection):
    objs = parts(toy_collection)
    bpy.data.objects.remove(objs["6.a Thigh.R"])
    select(objs["6.a Thigh.L"])
    undo_redo(bpy.ops.ellimann.mirror_ellipsoids)


def test_mirror_side_replacing(toy_collection):
    parts(toy_collection)["5.a Arm.R"].location.z += 0.1
    undo_redo(bpy.ops.ellimann.mirror_side, source="L", replace=True)


def test_relabel_axes(toy):
    reference = mannequin_to_collection(toy, name="Reference")
    turned = toy.copy(name="Turned")
    turned.rotation[0] = turned.rotation[0] @ CYCLE
    turned.semi_axes[0] = CYCLE.T @ turned.semi_axes[0]
    target = mannequin_to_collection(turned)
    select(parts(target)["1.a Head"])
    undo_redo(bpy.ops.ellimann.relabel_axes, reference=reference.name, scope="MANNEQUIN")


def test_symmetrize_central(toy):
    tilted = toy.copy()
    tilted.center[0, 0] = 0.02
    tilted.rotation[0] = rotation_from_vector((0.1, 0.2, 0.3))
    collection = mannequin_to_collection(tilted)
    select(parts(collection)["1.a Head"])
    undo_redo(bpy.ops.ellimann.symmetrize_central, scope="MANNEQUIN")


def test_register(toy):
    collection = mannequin_to_collection(toy.copy(center=toy.center + (0.3, -0.2, 0.5)))
    select(parts(collection)["1.a Head"])
    undo_redo(bpy.ops.ellimann.register_mannequin)


def test_build_cushions_twice(toy_collection):
    bpy.ops.ellimann.build_cushions(subdivisions=1)
    after = undo_redo(bpy.ops.ellimann.build_cushions, subdivisions=2)  # replaces the cushions built before
    assert len(after["objects"]) == 15


def test_measure_and_draw_sections(toy_collection):
    after = undo_redo(bpy.ops.ellimann.measure_mannequin, draw_sections=True)
    assert after["collections"]["toy"][3] and after["curves"]


def test_fix_frames(toy_collection):
    thigh = parts(toy_collection)["6.a Thigh.L"]
    thigh.scale.x *= -1
    select(thigh)
    undo_redo(bpy.ops.ellimann.fix_frames, scope="SELECTED")


def test_synthesize(tmp_path):
    bpy.context.scene.ellimann_synthesis.references = str(synthetic.write_reference_folder(tmp_path))
    after = undo_redo(bpy.ops.ellimann.synthesize_mannequin)
    assert any(name.startswith("ElliMann ") for name in after["collections"])


def test_drape():
    collection = mannequin_to_collection(make_apose_toy())
    select(parts(collection)["2.a Chest"])
    props = bpy.context.scene.ellimann_drape
    props.frames, props.edge = 4, 0.05
    after = undo_redo(bpy.ops.ellimann.drape_garment)
    assert after["frames"][2] == 4  # the drape shows its last frame


def rm_with_joints():
    """The Average RM (it has joints) as a collection, one of its pieces active."""
    collection = add_mannequin(Mannequin.load(REFERENCE_FOLDER / "average.json"))
    bpy.context.view_layer.objects.active = next(iter(collection.objects))
    return collection


def test_add_armature():
    rm_with_joints()
    after = undo_redo(bpy.ops.ellimann.add_armature)
    assert len(after["armatures"]) == 1


def test_apply_pose_and_rest():
    rm_with_joints()
    assert bpy.ops.ellimann.add_armature() == {"FINISHED"}
    undo_redo(bpy.ops.ellimann.apply_pose, pose="t_pose")
    after = undo_redo(bpy.ops.ellimann.apply_pose, pose="walk")
    assert len(after["actions"]) == 1
    undo_redo(bpy.ops.ellimann.rest_pose)


def test_build_skin_and_build_it_again_in_place():
    from ellimann_addon.blender.services.rig import build_rig
    from ellimann_addon.core.synthesis.shipped import named_reference_set

    average = named_reference_set("female").mannequins[4]
    collection = mannequin_to_collection(average)
    build_rig(collection, average)
    bpy.context.view_layer.objects.active = parts(collection)["1.a Cranium"]
    after = undo_redo(bpy.ops.ellimann.build_skin, level="PREVIEW")
    assert any(name.endswith("Skin") for name in after["objects"])
    parts(bpy.data.collections[average.name])["5.a Thigh.L"].location.x += 0.01  # undo made new data
    rebuilt = undo_redo(bpy.ops.ellimann.build_skin, level="PREVIEW")  # the same object, a new surface
    assert set(rebuilt["objects"]) == set(after["objects"]) and rebuilt["meshes"] != after["meshes"]
