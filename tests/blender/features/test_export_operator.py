"""Export Mannequin (File > Export, the sidebar): the active mannequin to .glb with extras or to MJCF, headless."""

import xml.etree.ElementTree as ET
from types import SimpleNamespace

import bpy
import pytest

from devkit.blender_scene import parts, select, state
from devkit.ui_recorder import draw_menu_function, draw_operator, draw_panel
from ellimann_addon.blender import ids, registry
from ellimann_addon.blender.bridge.convert import mannequin_to_collection
from ellimann_addon.blender.features import main_panel, menus
from ellimann_addon.blender.features.export.operator import (
    ELLIMANN_OT_export_mannequin,
    default_path,
    reconcile,
    with_extension,
)
from ellimann_addon.core.formats.glb import EXTRAS_KEY, read_glb_json


def geoms(path):
    return [g for g in ET.parse(path).getroot().iter("geom") if g.get("name") not in (None, "floor")]


def test_glb_with_extras_of_the_active_mannequin(toy, toy_collection, tmp_path, capfd):
    mannequin_to_collection(toy.copy(name="other"))
    select(parts(toy_collection)["6.a Thigh.L"])
    before = state()
    path = tmp_path / "out" / "toy.glb"
    assert bpy.ops.ellimann.export_mannequin(filepath=str(path)) == {"FINISHED"}
    doc = read_glb_json(path)
    assert sorted(n["name"] for n in doc["nodes"]) == sorted(toy.topology.names)  # the active one only
    assert doc["scenes"][0]["extras"][EXTRAS_KEY]["name"] == "toy"
    assert f"Info: Exported 'toy' (glTF) to {path}" in capfd.readouterr().out
    assert state() == before  # writing a file changes nothing in Blender's data
    assert [p.name for p in path.parent.iterdir()] == ["toy.glb"]


def test_the_extension_or_the_format_chooses_mjcf(toy, toy_collection, tmp_path, capfd):
    assert bpy.ops.ellimann.export_mannequin(filepath=str(tmp_path / "toy.xml")) == {"FINISHED"}
    assert sorted(g.get("name") for g in geoms(tmp_path / "toy.xml")) == sorted(toy.topology.names)
    assert all(g.get("type") == "ellipsoid" for g in geoms(tmp_path / "toy.xml"))
    assert bpy.ops.ellimann.export_mannequin(filepath=str(tmp_path / "hulls"), format="MJCF", cushions=True) == {
        "FINISHED"
    }
    shapes = [g.get("type") for g in geoms(tmp_path / "hulls.xml")]
    assert shapes.count("mesh") == len(toy.topology.cushion_pairs) == 3
    assert shapes.count("ellipsoid") == len(toy) - 6
    assert "(MJCF with cushion meshes)" in capfd.readouterr().out


def test_a_name_without_glb_or_xml_gets_the_formats_extension_as_in_the_file_browser(toy_collection, tmp_path):
    """A dot in a mannequin's name ("ElliMann 159.5-43") is no extension; execute() and check() agree."""
    cases = (
        ("ElliMann 159.5-43", "GLB", "ElliMann 159.5-43.glb"),
        ("ElliMann 159.5-43", "MJCF", "ElliMann 159.5-43.xml"),
        ("toy.obj", "GLB", "toy.obj.glb"),
    )
    for i, (name, kind, written) in enumerate(cases):
        assert with_extension(name, kind) == written  # what check() makes of the name
        path = tmp_path / str(i) / name
        assert bpy.ops.ellimann.export_mannequin(filepath=str(path), format=kind) == {"FINISHED"}
        assert [p.name for p in path.parent.iterdir()] == [written]
    # .glb or .xml (in any case) decides the format, whatever the format option says.
    assert bpy.ops.ellimann.export_mannequin(filepath=str(tmp_path / "toy.GLB"), format="MJCF") == {"FINISHED"}
    assert read_glb_json(tmp_path / "toy.GLB")["scenes"][0]["extras"][EXTRAS_KEY]["name"] == "toy"


def test_refuses_bad_paths_and_broken_mannequins_writing_nothing(toy_collection, tmp_path):
    with pytest.raises(RuntimeError, match="Choose a file name"):
        bpy.ops.ellimann.export_mannequin(filepath=f"{tmp_path}/")
    target = tmp_path / "toy.glb"
    target.write_bytes(b"previous")
    pelvis = parts(toy_collection)["3.a Pelvis"]
    pelvis.scale.x *= -1
    bpy.context.view_layer.update()
    for path in (target, tmp_path / "toy.xml"):
        with pytest.raises(RuntimeError, match="Fix 'toy' first: '3.a Pelvis'"):
            bpy.ops.ellimann.export_mannequin(filepath=str(path))
    assert target.read_bytes() == b"previous" and [p.name for p in tmp_path.iterdir()] == ["toy.glb"]


def test_refuses_a_glb_of_out_of_date_cushions_until_they_are_built_again(toy_collection, tmp_path):
    assert bpy.ops.ellimann.build_cushions() == {"FINISHED"}
    parts(toy_collection)["6.b Shin.L"].location.z += 0.02  # what a live update, an undo or a reload can leave
    bpy.context.view_layer.update()
    before = state()
    path = tmp_path / "toy.glb"
    with pytest.raises(
        RuntimeError,
        match=r"Cannot export 'toy': the cushions of 'toy' are out of date "
        r"\('6.a Thigh.L \+ 6.b Shin.L': .*\): Build Cushions first",
    ):
        bpy.ops.ellimann.export_mannequin(filepath=str(path))
    assert state() == before and not path.exists()
    # MJCF takes its cushion meshes from the ellipsoids, not from the built objects: nothing out of date.
    assert bpy.ops.ellimann.export_mannequin(filepath=str(tmp_path / "toy.xml"), cushions=True) == {"FINISHED"}
    assert bpy.ops.ellimann.build_cushions() == {"FINISHED"}
    assert bpy.ops.ellimann.export_mannequin(filepath=str(path)) == {"FINISHED"}
    assert "6.a Thigh.L + 6.b Shin.L" in {n["name"] for n in read_glb_json(path)["nodes"]}


def test_needs_an_active_mannequin():
    assert not bpy.ops.ellimann.export_mannequin.poll()
    bpy.ops.ellimann.new_mannequin()
    assert bpy.ops.ellimann.export_mannequin.poll()


class RestoredProperties:
    """An operator's properties as Blender hands them to invoke after an earlier run: the last-used values,
    which count as set unless ``ghost=False`` asks for what the caller set."""

    def __init__(self, restored=(), given=()):
        self.restored, self.given = set(restored), set(given)

    def is_property_set(self, name, ghost=True):
        return name in self.given or (ghost and name in self.restored)


class FileBrowser:
    def fileselect_add(self, operator):
        self.operator = operator


def invoke_export(context, properties, **values):
    """Run the operator's invoke on a stand-in (headless Blender executes instead of invoking)."""
    operator = SimpleNamespace(properties=properties, filepath="", format="GLB", cushions=False, last_format="")
    vars(operator).update(values)
    browser = FileBrowser()
    fake = SimpleNamespace(active_object=context.active_object, collection=context.collection, window_manager=browser)
    assert ELLIMANN_OT_export_mannequin.invoke(operator, fake, None) == {"RUNNING_MODAL"}
    assert browser.operator is operator
    return operator


def test_each_export_suggests_the_active_mannequin_not_the_last_run(toy, toy_collection):
    rna = bpy.ops.ellimann.export_mannequin.get_rna_type().properties
    assert rna["filepath"].is_skip_save  # Blender restores the last-used filepath otherwise (A's file for B)
    assert rna["filepath"].subtype == "FILE_PATH" and rna["filepath"].description
    other = mannequin_to_collection(toy.copy(name="Other"))
    select(parts(other)["1.a Head"])
    # The last export (of toy, with cushion meshes) is what Blender restores: Other has no cushions.
    operator = invoke_export(bpy.context, RestoredProperties(restored={"cushions"}), cushions=True)
    assert (operator.filepath, operator.cushions) == ("Other.glb", False)
    operator = invoke_export(bpy.context, RestoredProperties(given={"cushions"}), cushions=True, format="MJCF")
    assert (operator.filepath, operator.cushions, operator.last_format) == ("Other.xml", True, "MJCF")  # as given
    select(parts(toy_collection)["1.a Head"])
    assert bpy.ops.ellimann.build_cushions() == {"FINISHED"}
    operator = invoke_export(bpy.context, RestoredProperties())
    assert (operator.filepath, operator.cushions) == ("toy.glb", True)


def test_extension_and_format_follow_each_other():
    assert with_extension("/a/toy.glb", "MJCF") == "/a/toy.xml"
    assert with_extension("/a/ElliMann 159.5-43", "GLB") == "/a/ElliMann 159.5-43.glb"
    assert reconcile("/a/toy.glb", "MJCF", "GLB") == ("/a/toy.xml", "MJCF")  # the format was changed
    assert reconcile("/a/toy.xml", "GLB", "GLB") == ("/a/toy.xml", "MJCF")  # the file name was changed
    assert reconcile("/a/toy", "GLB", "GLB") == ("/a/toy.glb", "GLB")
    assert default_path("toy (A-pose)", "/work/scenes/traced.blend", "MJCF") == "/work/scenes/toy (A-pose).xml"
    assert default_path("a/b", "", "GLB") == "a_slash_b.glb"  # an unsaved file: Blender's current folder


def test_reachable_from_file_export_the_object_menu_and_the_main_panel(toy_collection):
    export_entry = dict(registry.MENU_ENTRIES)["TOPBAR_MT_file_export"]
    assert draw_menu_function(export_entry).operators() == [ids.EXPORT_MANNEQUIN]
    assert ids.EXPORT_MANNEQUIN in draw_panel(menus.ELLIMANN_MT_object).operators()
    assert ids.EXPORT_MANNEQUIN in draw_panel(main_panel.ELLIMANN_PT_main).operators()


def test_options_draw():
    recorder = draw_operator(ELLIMANN_OT_export_mannequin, format="GLB")
    assert recorder.props() == ["format", "cushions"]
