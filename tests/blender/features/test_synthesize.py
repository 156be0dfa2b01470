"""The Synthesize operator, live updates, presets and the sub-panel, headless."""

import os
import pathlib
import time

import bpy
import numpy as np
import pytest

from devkit import synthetic
from devkit.blender_scene import state
from devkit.ui_recorder import Recorder, draw_panel
from ellimann_addon.blender import ids
from ellimann_addon.blender.bridge import convert
from ellimann_addon.blender.bridge.built import is_stale
from ellimann_addon.blender.bridge.selection import part_lookup
from ellimann_addon.blender.features.synthesize import live, panel, presets
from ellimann_addon.blender.features.synthesize import props as synthesis_props
from ellimann_addon.core.constants import CUSHION_LEVEL, RANGES, REFERENCE_MEASUREMENTS, TABLE_2_5
from ellimann_addon.core.geometry.cushion import cushion_vertices
from ellimann_addon.core.geometry.mesh import convexity_defect, is_closed_manifold
from ellimann_addon.core.measurements import ABSURD_LIMITS, MEASUREMENTS
from ellimann_addon.core.synthesis.reference_set import load_reference_set
from ellimann_addon.core.synthesis.shipped import SHIPPED_SETS
from ellimann_addon.core.synthesis.synthesize import synthesize as core_synthesize


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return str(synthetic.write_reference_folder(tmp_path_factory.mktemp("rm")))


@pytest.fixture
def props(folder):
    props = bpy.context.scene.ellimann_synthesis
    props.reference_set, props.references = "FOLDER", folder
    for key, value in zip(MEASUREMENTS, (159.0, 43.0, 117.0, 104.0, 117.0)):
        setattr(props, key.lower(), value)
    return props


def test_fields_are_in_cm_with_soft_limits_from_L_and_hard_limits_from_the_absurd_ones():
    rna = synthesis_props.ELLIMANN_PG_synthesis.bl_rna.properties
    for key in MEASUREMENTS:
        field = rna[key.lower()]
        assert (field.soft_min, field.soft_max) == pytest.approx(RANGES[key])
        assert (field.hard_min, field.hard_max) == pytest.approx(ABSURD_LIMITS[key])
        assert "cm" in field.description


def test_every_option_and_choice_has_a_tooltip():
    rna = synthesis_props.ELLIMANN_PG_synthesis.bl_rna.properties
    for name in ("mode", "output", "normalize", "metric", "power", "live", "target", "references"):
        assert len(rna[name].description) > 20, name
    for name in ("mode", "output", "normalize", "metric"):
        for item in rna[name].enum_items:
            assert len(item.description) > 10, (name, item.identifier)


def test_synthesize_makes_a_new_collection_named_after_the_measurements(props):
    assert bpy.ops.ellimann.synthesize_mannequin() == {"FINISHED"}
    collection = bpy.data.collections["ElliMann 159-43-117-104-117"]
    assert props.target == collection
    assert collection.ellimann.role == "synthesized" and collection.ellimann.has_measured
    assert tuple(collection.ellimann.measured) == pytest.approx((159.0, 43.0, 117.0, 104.0, 117.0), rel=1e-4)
    mannequin = convert.collection_to_mannequin(collection)
    assert mannequin.measure() == pytest.approx(dict(zip(MEASUREMENTS, collection.ellimann.target)), rel=1e-4)
    # A second click makes a second mannequin; the first is left alone.
    props.he = 160.0
    assert bpy.ops.ellimann.synthesize_mannequin() == {"FINISHED"}
    assert props.target.name == "ElliMann 160-43-117-104-117"
    assert len(convert.mannequin_collections()) == 2


def test_idw_mode_and_cushions(props):
    props.mode, props.output, props.metric, props.power = "IDW", "CUSHIONS", "NORMALIZED", 3.0
    props.normalize = "NONE"
    assert bpy.ops.ellimann.synthesize_mannequin() == {"FINISHED"}
    collection = props.target
    cushions = [o for o in bpy.data.objects if o.ellimann.kind == "CUSHION"]
    reference = synthetic.make_reference_set()
    assert len(cushions) == len(reference.topology.cushion_pairs)
    expected, _, _ = core_synthesize(
        reference,
        dict(zip(MEASUREMENTS, collection.ellimann.target)),
        mode="idw",
        metric="normalized",
        power=3.0,
        normalize="none",
    )
    got = convert.collection_to_mannequin(collection).reordered(expected.topology)
    np.testing.assert_allclose(got.center, expected.center, atol=1e-6)


def test_a_failure_is_reported_and_changes_nothing(props, tmp_path):
    props.references = str(tmp_path / "nowhere")
    with pytest.raises(RuntimeError, match="does not exist"):
        bpy.ops.ellimann.synthesize_mannequin()
    assert convert.mannequin_collections() == [] and len(bpy.data.objects) == 0


def test_outside_L_is_synthesized_with_a_warning(props):
    props.he = 180.0
    assert bpy.ops.ellimann.synthesize_mannequin() == {"FINISHED"}
    assert "He = 180 cm is outside the reference range" in props.status


def test_live_updates_the_last_mannequin_in_place(props):
    bpy.ops.ellimann.synthesize_mannequin()
    collection = props.target
    objects = {o.name: o for o in collection.objects}
    before = convert.collection_to_mannequin(collection)
    props.live = True
    times = []
    for value in (150.0, 155.5, 162.0, 168.0):
        start = time.perf_counter()
        props.he = value  # the property's update callback does the work
        times.append(time.perf_counter() - start)
    print(
        f"\nlive update (exact mode, {len(objects)} ellipsoids): "
        f"{1e3 * min(times):.1f}-{1e3 * max(times):.1f} ms per change"
    )
    assert props.target == collection and {o.name: o for o in collection.objects} == objects
    assert collection.name == "ElliMann 168-43-117-104-117"
    assert collection.ellimann.measured[0] == pytest.approx(168.0, rel=1e-4)
    after = convert.collection_to_mannequin(collection)
    assert np.abs(after.center - before.center).max() > 0.01
    assert props.live_ms > 0
    assert len(convert.mannequin_collections()) == 1


def cushion_objects():
    return sorted((o for o in bpy.data.objects if o.ellimann.kind == "CUSHION"), key=lambda o: o.name)


def local_vertices(obj):
    return convert.mesh_vertices(obj.data)


def test_live_moves_the_cushions_in_place_then_rebuilds_them_exactly(props):
    props.output = "CUSHIONS"
    bpy.ops.ellimann.synthesize_mannequin()
    collection = props.target
    before = {o.name: (o.data.as_pointer(), local_vertices(o)) for o in cushion_objects()}
    faces = {o.name: [tuple(p.vertices) for p in o.data.polygons] for o in cushion_objects()}
    props.live = True
    props.he = 165.0  # every part depends on He
    cushions = cushion_objects()
    assert [o.name for o in cushions] == sorted(before)  # the same objects and meshes, moved
    assert all(o.data.as_pointer() == before[o.name][0] for o in cushions)
    assert all([tuple(p.vertices) for p in o.data.polygons] == faces[o.name] for o in cushions)
    mannequin = convert.collection_to_mannequin(collection)
    names = mannequin.topology.names
    for obj in cushions:  # vertices: the support points of the moved ellipsoids, in the first one's frame
        first, second = names.index(obj.ellimann.part_name), names.index(obj.ellimann.partner)
        expected = cushion_vertices(
            mannequin.rotation, mannequin.center, mannequin.semi_axes, [(first, second)], CUSHION_LEVEL
        )[0]
        np.testing.assert_allclose(local_vertices(obj), expected, atol=1e-6)
        assert np.abs(local_vertices(obj) - before[obj.name][1]).max() > 1e-4
        np.testing.assert_allclose(np.array(obj.matrix_world)[:3, 3], mannequin.center[first], atol=1e-6)
    print(f"\nlive update with {len(cushions)} cushions: {props.live_ms:.1f} ms")
    # The kept faces were convex for the old ellipsoids: out of date until the fields are still.
    parts = part_lookup(collection)
    assert all(is_stale(o, parts) for o in cushions)
    assert bpy.app.timers.is_registered(live._settle_timer)
    bpy.app.timers.unregister(live._settle_timer)
    assert live._settle_timer() is None  # what the timer runs, once
    settled = cushion_objects()
    assert len(settled) == len(cushions) and not any(is_stale(o, parts) for o in settled)
    for obj in settled:
        vertices, triangles = convert.mesh_vertices(obj.data), np.array([tuple(p.vertices) for p in obj.data.polygons])
        assert is_closed_manifold(triangles) and convexity_defect(vertices, triangles) < 1e-6
    assert live.settle_live(bpy.context.scene) == 0  # nothing left to do
    bpy.data.collections.remove(props.target)
    props.hi = 120.0  # no target left: nothing to update, no error
    assert props.target is None


def moved_live_cushions(props):
    """Synthesize with cushions, then one live update: the cushions are moved in place, out of date."""
    props.output = "CUSHIONS"
    bpy.ops.ellimann.synthesize_mannequin()
    props.live = True
    props.he = 165.0
    assert all(is_stale(o, part_lookup(props.target)) for o in cushion_objects())
    return props.target


def test_the_settle_timer_works_in_the_live_scene_whatever_scene_the_context_shows(props):
    scene = bpy.context.scene
    target = moved_live_cushions(props)
    other = bpy.data.scenes.new("Other")
    bpy.app.timers.unregister(live._settle_timer)
    with bpy.context.temp_override(scene=other, view_layer=other.view_layers[0]):  # another window's context
        assert live._settle_timer() is None
    assert cushion_objects() and not any(is_stale(o, part_lookup(target)) for o in cushion_objects())
    layer = scene.view_layers[0]
    paired = [o for o in target.objects if o.ellimann.partner]
    assert paired and all(o.hide_get(view_layer=layer) and o.hide_render for o in paired)
    assert not any(o.hide_get(view_layer=layer) for o in target.objects if not o.ellimann.partner)


def test_cushions_that_cannot_be_settled_are_left_as_they_were_with_one_line_on_the_console(props, capsys):
    target = moved_live_cushions(props)
    bpy.context.view_layer.layer_collection.children[target.name].exclude = True  # not in the view layer
    before = state()
    capsys.readouterr()
    assert live.settle_live(bpy.context.scene) == 0
    assert state() == before and all(is_stale(o, part_lookup(target)) for o in cushion_objects())
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"ElliMann: cushions of '{target.name}' not rebuilt: cannot hide ") and "\n" not in err
    assert props.status.startswith("Cushions not rebuilt: cannot hide ")
    assert "is not in view layer 'ViewLayer'" in props.status


def live_stale():
    """Out of date or not, each cushion of the current scene's live target (looked up again: undo and file
    loads replace Blender's data, so references held from before are invalid)."""
    target = bpy.context.scene.ellimann_synthesis.target
    return [is_stale(o, part_lookup(target)) for o in cushion_objects()]


def fire_settle_timer():
    """What Blender does once the timer is due: it is registered, and runs once."""
    assert bpy.app.timers.is_registered(live._settle_timer)
    bpy.app.timers.unregister(live._settle_timer)
    assert live._settle_timer() is None
    assert live_stale() and not any(live_stale())


def test_undo_and_redo_to_moved_cushions_settle_them_again(props):
    props.output = "CUSHIONS"
    bpy.ops.ellimann.synthesize_mannequin()
    props.live = True
    bpy.ops.ed.undo_push(message="Synthesize")
    for attr, value in (("he", 165.0), ("hi", 125.0)):
        setattr(bpy.context.scene.ellimann_synthesis, attr, value)
        bpy.ops.ed.undo_push(message=attr)  # what releasing the slider records: moved, out-of-date cushions
        fire_settle_timer()  # afterwards, recorded by no step
    assert bpy.ops.ed.undo() == {"FINISHED"}  # back to He 165 as recorded: moved cushions
    assert all(live_stale())
    fire_settle_timer()
    assert bpy.ops.ed.redo() == {"FINISHED"}  # Hi 125 as recorded: the cushions Hi moved are out of date
    assert any(live_stale())
    fire_settle_timer()
    props = bpy.context.scene.ellimann_synthesis
    props.live = False  # with Live off the handler leaves out-of-date cushions alone
    next(o for o in props.target.objects if o.ellimann.partner).location.x += 0.01
    bpy.context.view_layer.update()
    live.settle_restored(bpy.context.scene, None)
    assert any(live_stale()) and not bpy.app.timers.is_registered(live._settle_timer)


def test_a_file_saved_before_the_cushions_settled_settles_them_when_opened(props, tmp_path):
    moved_live_cushions(props)
    path = tmp_path / "live.blend"
    assert bpy.ops.wm.save_as_mainfile(filepath=str(path)) == {"FINISHED"}
    bpy.ops.wm.read_homefile(use_empty=True)  # a file load removes the timer
    assert not bpy.app.timers.is_registered(live._settle_timer)
    assert bpy.ops.wm.open_mainfile(filepath=str(path)) == {"FINISHED"}
    assert all(live_stale())
    fire_settle_timer()


def test_live_rebuilds_the_cushions_once_if_one_is_missing(props):
    props.output = "CUSHIONS"
    bpy.ops.ellimann.synthesize_mannequin()
    count = len(cushion_objects())
    bpy.data.objects.remove(cushion_objects()[0])
    props.live = True  # turning Live on updates once: all cushions rebuilt, exact
    cushions = cushion_objects()
    assert len(cushions) == count and not any(is_stale(o, part_lookup(props.target)) for o in cushions)
    assert not bpy.app.timers.is_registered(live._settle_timer)  # exact already: nothing to settle
    moved = {o.name: (o.data.as_pointer(), local_vertices(o)) for o in cushions}
    props.he = 162.0  # complete again: moved in place
    assert {o.name: o.data.as_pointer() for o in cushion_objects()} == {k: v[0] for k, v in moved.items()}
    assert all(np.abs(local_vertices(o) - moved[o.name][1]).max() > 1e-5 for o in cushion_objects())
    assert bpy.app.timers.is_registered(live._settle_timer)  # moved: out of date until settled


def test_a_preset_makes_one_live_update(props, monkeypatch):
    bpy.ops.ellimann.synthesize_mannequin()
    props.live = True
    calls = []
    real = live.live_update
    monkeypatch.setattr(live, "live_update", lambda scene: calls.append(scene) or real(scene))
    preset = presets.SHIPPED_PRESETS / "Table 2.5 (3).py"
    bpy.ops.script.execute_preset(filepath=str(preset), menu_idname="ELLIMANN_MT_measurement_presets")
    assert len(calls) == 1
    assert tuple(props.target.ellimann.measured) == pytest.approx(TABLE_2_5[2], rel=1e-4)
    props.live = False
    bpy.ops.script.execute_preset(filepath=str(preset), menu_idname="ELLIMANN_MT_measurement_presets")
    assert len(calls) == 1  # live off: none
    props.he = 150.0
    props.live = True
    props.he = 151.0  # held no longer: every change updates again
    assert len(calls) == 3


def test_a_preset_is_one_undo_step_with_its_live_update(props):
    props.output = "CUSHIONS"
    bpy.ops.ellimann.synthesize_mannequin()
    props.live = True
    bpy.ops.ed.undo_push(message="Before")
    before = state()
    preset = presets.SHIPPED_PRESETS / "Table 2.5 (3).py"
    # As the preset menu runs it (a click: undo=True); script.execute_preset alone pushes no step.
    assert bpy.ops.ellimann.apply_measurement_preset("EXEC_DEFAULT", True, filepath=str(preset)) == {"FINISHED"}
    after = state()
    measured = tuple(bpy.context.scene.ellimann_synthesis.target.ellimann.measured)
    assert after != before and measured == pytest.approx(TABLE_2_5[2], rel=1e-4)
    assert presets.ELLIMANN_MT_measurement_presets.bl_label == "Table 2.5 (3)"  # the menu shows it
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert state() == before
    assert [getattr(bpy.context.scene.ellimann_synthesis, m.lower()) for m in MEASUREMENTS] == [
        159.0,
        43.0,
        117.0,
        104.0,
        117.0,
    ]
    assert bpy.ops.ed.redo() == {"FINISHED"}
    assert state() == after


def test_a_missing_preset_is_refused_and_a_broken_one_can_be_undone(props, tmp_path):
    before = state()
    with pytest.raises(RuntimeError, match="No measurement preset at"):
        bpy.ops.ellimann.apply_measurement_preset(filepath=str(tmp_path / "gone.py"))
    assert state() == before and props.he == 159.0
    broken = tmp_path / "broken.py"
    broken.write_text("import bpy\nprops = bpy.context.scene.ellimann_synthesis\nprops.he = 150.0\nprops.sh = 'wide'\n")
    with pytest.raises(RuntimeError, match="Preset 'broken.py' failed: .*Failed to execute the preset"):
        bpy.ops.ellimann.apply_measurement_preset(filepath=str(broken))
    assert props.he == 150.0  # what it set before failing stays: the operator finished, one undo takes it back


def test_a_live_target_whose_name_is_taken_keeps_its_suffix(props):
    taken = "ElliMann 160-43-117-104-117"
    mine = convert.new_collection(taken)
    bpy.ops.ellimann.synthesize_mannequin()
    target = props.target
    props.live = True
    props.he = 160.0
    assert target.name == taken + ".001" and mine.name == taken
    assert not live.rename_live_target(target, taken)  # next updates leave the name alone
    props.mode = "IDW"
    assert target.name == taken + ".001" and mine.name == taken
    props.he = 161.0
    assert target.name == "ElliMann 161-43-117-104-117"
    bpy.data.collections.remove(mine)
    props.he = 160.0
    assert target.name == taken  # the name is free again


def shipped_presets():
    return sorted(presets.SHIPPED_PRESETS.glob("*.py"))


def test_shipped_presets_hold_the_reference_and_table_2_5_measurements_and_choose_their_set(props):
    """Female presets leave a folder chosen (the user's own set) but leave the male set; male ones choose it."""
    expected = {
        f"RM {k.replace('_', ' ').title()}": ([v[m] for m in MEASUREMENTS], "FEMALE")
        for k, v in REFERENCE_MEASUREMENTS.items()
    }
    expected.update({f"Table 2.5 ({i})": (list(row), "FEMALE") for i, row in enumerate(TABLE_2_5, 1)})
    male = load_reference_set(SHIPPED_SETS["male"])
    expected.update(
        {f"Male RM {k.replace('_', ' ').title()}": (list(v), "MALE") for k, v in zip(male.names, male.measurements)}
    )
    assert {p.stem for p in shipped_presets()} == set(expected)
    for path in shipped_presets():
        values, chosen = expected[path.stem]
        fine = f"{chosen}_FINE"  # from a set of the fine topology: its twin of the preset's sex
        for before, after in (
            ("FOLDER", "FOLDER" if chosen == "FEMALE" else chosen),
            ("MALE", chosen),
            ("FEMALE_FINE", fine),
            ("MALE_FINE", fine),
        ):
            props.reference_set = before
            bpy.ops.script.execute_preset(filepath=str(path), menu_idname="ELLIMANN_MT_measurement_presets")
            assert [getattr(props, m.lower()) for m in MEASUREMENTS] == pytest.approx(values)
            assert props.reference_set == after, (path.stem, before)


def test_users_can_save_and_remove_their_own_presets(props):
    props.he, props.hi = 161.5, 121.0
    assert bpy.ops.ellimann.add_measurement_preset(name="My Client") == {"FINISHED"}
    user = pathlib.Path(bpy.utils.user_resource("SCRIPTS", path=os.path.join("presets", presets.PRESET_SUBDIR)))
    saved = user / "My_Client.py"
    assert saved.is_file()
    props.he = props.hi = 150.0
    bpy.ops.script.execute_preset(filepath=str(saved), menu_idname="ELLIMANN_MT_measurement_presets")
    assert (props.he, props.hi) == pytest.approx((161.5, 121.0))
    menu = draw_panel(presets.ELLIMANN_MT_measurement_presets)
    assert set(menu.operators()) == {ids.APPLY_MEASUREMENT_PRESET}  # an undo step per preset
    assert str(saved) in [kw["props"].get("filepath") for kind, kw in menu.log if kind == "operator"]
    names = [kw.get("text") for kind, kw in menu.log if kind == "operator"]
    assert "My Client" in names and "RM Small Slim" in names and "Table 2.5 (10)" in names
    assert names.index("RM Average") < names.index("Table 2.5 (1)") < names.index("Table 2.5 (10)")
    assert bpy.ops.ellimann.add_measurement_preset(name="My Client", remove_name=True) == {"FINISHED"}
    assert not saved.exists()


def test_the_panel_draws_request_options_and_measured_values(props):
    recorder = draw_panel(panel.ELLIMANN_PT_synthesize)
    assert [p for p in recorder.props() if p in ("he", "sh", "br", "wa", "hi")] == ["he", "sh", "br", "wa", "hi"]
    for name in ("mode", "output", "normalize", "metric", "power", "live", "reference_set", "references"):
        assert name in recorder.props()
    props.reference_set = "MALE"
    assert "references" not in draw_panel(panel.ELLIMANN_PT_synthesize).props()  # the folder only for Folder
    props.reference_set = "FOLDER"
    assert "ellimann.synthesize_mannequin" in recorder.operators()
    assert "ellimann.add_measurement_preset" in recorder.operators()
    label = presets.ELLIMANN_MT_measurement_presets.bl_label  # the last preset chosen
    assert ("menu", {"menu": "ELLIMANN_MT_measurement_presets", "text": label}) in recorder.log
    assert "m_T (cm)" not in recorder.labels()
    bpy.ops.ellimann.synthesize_mannequin()
    labels = draw_panel(panel.ELLIMANN_PT_synthesize).labels()
    assert "m_T (cm)" in labels and "159.00" in labels and "117.00" in labels


def test_the_panel_is_a_sub_panel_registered_with_the_add_on():
    """Registered after its parent ELLIMANN_PT_main (``registry.CLASSES``), between the authoring tools' panels
    and Drape (test_ids checks the ids themselves)."""
    from ellimann_addon.blender import ids, registry

    classes = list(registry.CLASSES)
    assert classes.index(registry.main_panel.ELLIMANN_PT_main) < classes.index(panel.ELLIMANN_PT_synthesize)
    assert hasattr(bpy.types, ids.PANEL_SYNTHESIZE) and hasattr(bpy.types, ids.PANEL_MAIN)
    cls = panel.ELLIMANN_PT_synthesize
    assert (cls.bl_idname, cls.bl_parent_id) == (ids.PANEL_SYNTHESIZE, ids.PANEL_MAIN)
    assert max(ids.PANEL_ORDER.values()) < cls.bl_order < ids.DRAPE_ORDER


def test_recorder_catches_a_misspelt_property(props):
    with pytest.raises(AttributeError):
        Recorder().prop(props, "height")


def test_the_reference_set_choice_keeps_the_numbers_files_store(props):
    """A .blend stores an enum's number: Folder stayed 2 when the fine sets came (a file saved with Folder must not
    reopen with another set)."""
    items = props.bl_rna.properties["reference_set"].enum_items
    assert {item.identifier: item.value for item in items} == {
        "FEMALE": 0,
        "MALE": 1,
        "FOLDER": 2,
        "FEMALE_FINE": 3,
        "MALE_FINE": 4,
    }
