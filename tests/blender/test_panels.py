"""Panel and menu draw functions, run headless against the recording layout."""

import bpy
import pytest

from devkit.blender_scene import parts, select
from devkit.ui_recorder import Recorder, draw_menu_function, draw_panel
from ellimann_addon.blender import ids, registry
from ellimann_addon.blender.bridge.convert import write_measured
from ellimann_addon.blender.features import menus
from ellimann_addon.blender.features.cushions.panel import ELLIMANN_PT_cushions
from ellimann_addon.blender.features.main_panel import ELLIMANN_PT_main
from ellimann_addon.blender.features.part.panel import ELLIMANN_PT_part
from ellimann_addon.blender.features.references import panel as references_panel
from ellimann_addon.blender.features.synthesize import panel as synthesize_panel
from ellimann_addon.blender.features.synthesize import presets as synthesize_presets


@pytest.mark.parametrize("panel", registry.panels(), ids=lambda c: c.__name__)
def test_every_panel_draws_in_an_empty_file(panel):
    draw_panel(panel)


def test_main_panel_without_mannequin_offers_a_new_one():
    recorder = draw_panel(ELLIMANN_PT_main)
    assert "No active mannequin" in recorder.labels()
    assert recorder.operators() == [ids.NEW_MANNEQUIN]


def test_main_panel_shows_the_active_mannequin_with_measured_and_target_values(toy, toy_collection):
    recorder = draw_panel(ELLIMANN_PT_main)
    assert "toy" in recorder.labels() and "Not measured yet" in recorder.labels() and recorder.props() == ["role"]
    toy_collection.ellimann.has_target = True
    toy_collection.ellimann.target = (160.0, 40.0, 90.0, 70.0, 95.0)
    write_measured(toy_collection, toy.measure())
    labels = draw_panel(ELLIMANN_PT_main).labels()
    assert "12 ellipsoids, 0 cushions" in labels
    assert f"{toy.measure()['Br']:.2f}" in labels and "90.00" in labels


@pytest.mark.parametrize("panel", registry.panels(), ids=lambda c: c.__name__)
def test_every_panel_draws_with_a_mannequin_part_active(panel, toy_collection):
    select(parts(toy_collection)["6.a Thigh.L"])
    bpy.ops.ellimann.build_cushions(subdivisions=1)
    bpy.ops.ellimann.measure_mannequin()
    draw_panel(panel)


def test_part_panel_shows_the_fields_and_offers_a_fix_for_a_broken_frame(toy_collection):
    obj = parts(toy_collection)["6.a Thigh.L"]
    select(obj)
    recorder = draw_panel(ELLIMANN_PT_part)
    assert recorder.props() == ["part_name", "side", "region", "girth", "partner", "depends"]
    assert recorder.operators() == []
    obj.scale.x *= -1
    bpy.context.view_layer.update()
    recorder = draw_panel(ELLIMANN_PT_part)
    assert recorder.operators() == [ids.FIX_FRAMES]
    assert any("left-handed" in text for text in recorder.labels())


def test_part_panel_is_hidden_for_other_objects_and_brief_for_built_ones(toy_collection):
    plain = bpy.data.objects.new("Plain", None)
    bpy.context.scene.collection.objects.link(plain)
    select(plain)
    assert not ELLIMANN_PT_part.poll(bpy.context)
    select(parts(toy_collection)["6.a Thigh.L"])
    bpy.ops.ellimann.build_cushions(subdivisions=1)
    select(toy_collection.children[0].objects[0])
    recorder = draw_panel(ELLIMANN_PT_part)
    assert recorder.props() == ["part_name"] and "Cushion built by ElliMann" in recorder.labels()


def test_cushion_panel_flags_out_of_date_cushions(toy_collection):
    bpy.ops.ellimann.build_cushions(subdivisions=1)
    assert not any("out of date" in t for t in draw_panel(ELLIMANN_PT_cushions).labels())
    parts(toy_collection)["2.b Belly"].location.y += 0.02
    bpy.context.view_layer.update()
    assert "1 out of date: build again" in draw_panel(ELLIMANN_PT_cushions).labels()


def test_menus_reach_every_operator():
    recorder = draw_panel(menus.ELLIMANN_MT_object)
    reached = set(recorder.operators())
    for _, draw in registry.MENU_ENTRIES:
        layout = draw_menu_function(draw)
        reached.update(layout.operators())
        assert isinstance(layout, Recorder)
    everything = {v for k, v in vars(ids).items() if isinstance(v, str) and v.startswith("ellimann.")}
    # Saving a measurement preset belongs beside the preset menu, in the Synthesize panel; applying one, in it.
    assert ids.ADD_MEASUREMENT_PRESET in draw_panel(synthesize_panel.ELLIMANN_PT_synthesize).operators()
    presets_menu = synthesize_presets.ELLIMANN_MT_measurement_presets
    assert set(draw_panel(presets_menu).operators()) == {ids.APPLY_MEASUREMENT_PRESET}
    # Adding and removing a reference set's bodies belongs in its panel's list of bodies.
    bodies = bpy.context.scene.ellimann_references.bodies
    bodies.add()
    assert {ids.ADD_REFERENCE_BODIES, ids.REMOVE_REFERENCE_BODY} <= set(
        draw_panel(references_panel.ELLIMANN_PT_references).operators()
    )
    bodies.clear()
    assert reached == everything - {
        ids.ADD_MEASUREMENT_PRESET,
        ids.APPLY_MEASUREMENT_PRESET,
        ids.ADD_REFERENCE_BODIES,
        ids.REMOVE_REFERENCE_BODY,
    }


def test_recorder_refuses_misspelt_icons():
    recorder = Recorder()
    recorder.label(text="fine", icon="MOD_CLOTH")
    recorder.operator(ids.NEW_MANNEQUIN, icon="NONE")
    for draw in (
        lambda: recorder.label(text="x", icon="MOD_CLOTHES"),
        lambda: recorder.operator(ids.NEW_MANNEQUIN, icon="outliner_collection"),
        lambda: recorder.prop(bpy.context.scene.ellimann_drape, "garment", icon="CLOTH"),
        lambda: recorder.menu(menus.ELLIMANN_MT_object.bl_idname, icon="ELLIMANN"),
    ):
        with pytest.raises(ValueError, match="is not a Blender icon name"):
            draw()
    assert [kind for kind, _ in recorder.log] == ["label", "operator"]


def test_menu_entries_are_appended_to_blender_menus():
    for menu, draw in registry.MENU_ENTRIES:
        assert draw in getattr(bpy.types, menu)._dyn_ui_initialize()
