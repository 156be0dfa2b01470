"""Tracing that remembers (Fit Ellipsoid records its selection, kept in .blend and JSON) and Build Reference Set
(refusals change nothing; a build is written as a reference-set folder and loaded into a new collection)."""

import bpy
import numpy as np
import pytest

from devkit.blender_scene import edit_with_selection, reference_mesh, select, state
from ellimann_addon.blender.bridge.bodies import body_mesh, mesh_fingerprint
from ellimann_addon.blender.bridge.convert import collection_to_mannequin, mannequin_to_collection
from ellimann_addon.blender.features.references import operators
from ellimann_addon.core.fitting.body_mesh import connectivity_fingerprint
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.synthesis.manifest import read_manifest
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER, load_reference_set


def _fitted_part(chosen, name="4.a Half"):
    obj = reference_mesh(np.eye(3), (0.0, 0.0, 1.0), np.array((0.3, 0.2, 0.1)))
    edit_with_selection(obj, chosen)
    assert bpy.ops.ellimann.fit_ellipsoid(mode="enclosing", part_name=name) == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj, bpy.context.view_layer.active_layer_collection.collection


def test_fit_records_which_vertices_of_which_mesh(tmp_path):
    chosen = np.arange(40, 90)
    obj, collection = _fitted_part(chosen)
    trace = collection_to_mannequin(collection).traces["4.a Half"]
    assert trace.mesh == obj.name and trace.vertex_count == len(obj.data.vertices) and trace.method == "enclosing"
    assert np.array_equal(trace.vertices, chosen)
    polygons = [list(p.vertices) for p in obj.data.polygons]
    assert trace.edges_crc == connectivity_fingerprint(polygons) == mesh_fingerprint(obj.data)


def test_selections_survive_json_and_blend_save_and_load(tmp_path):
    chosen = np.arange(0, 300, 3)
    _, collection = _fitted_part(chosen)
    mannequin = collection_to_mannequin(collection)
    mannequin.save(tmp_path / "base.json")
    names = (collection.name, mannequin_to_collection(Mannequin.load(tmp_path / "base.json"), name="Again").name)
    path = str(tmp_path / "base.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=path)
    for name in names:
        trace = collection_to_mannequin(bpy.data.collections[name]).traces["4.a Half"]
        assert np.array_equal(trace.vertices, chosen)


def test_the_shipped_base_blend_carries_its_selections():
    bpy.ops.wm.open_mainfile(filepath=str(REFERENCE_FOLDER / "base_mannequin.blend"))
    collection = next(c for c in bpy.data.collections if c.ellimann.is_mannequin)
    from_blend = collection_to_mannequin(collection).traces
    from_json = Mannequin.load(REFERENCE_FOLDER / "base_mannequin.json").traces
    assert {k: t.to_dict() for k, t in from_blend.items()} == {k: t.to_dict() for k, t in from_json.items()}


def _scene_for_build(tmp_path, bodies=3):
    props = bpy.context.scene.ellimann_references
    base = mannequin_to_collection(Mannequin.load(REFERENCE_FOLDER / "base_mannequin.json"), name="Base")
    props.base = base
    meshes = [
        reference_mesh(np.eye(3), (0.5 * i, 0.0, 1.0), np.array((0.2, 0.2, 0.5)), name=f"body{i}")
        for i in range(bodies)
    ]
    select(*meshes)
    assert bpy.ops.ellimann.add_reference_bodies() == {"FINISHED"}
    for i, row in enumerate(props.bodies):
        row.target = (150.0 + 5 * i, 40.0, 100.0, 90.0, 100.0)
    props.folder = str(tmp_path / "set")
    return props


@pytest.mark.parametrize(
    "case, words",
    [
        ("fewer bodies", "at least 3 bodies, got 2"),
        ("other mesh", "642 vertices, the base was traced on 'reference_female' with 13348"),
        ("no folder", "Choose the folder"),
    ],
)
def test_build_refuses_bad_input_and_changes_nothing(tmp_path, case, words):
    props = _scene_for_build(tmp_path)
    if case == "fewer bodies":
        props.bodies.remove(2)
        props.bodies.add()  # an empty row: not a body
    if case == "no folder":
        props.folder = ""
    before = state()
    with pytest.raises(RuntimeError, match=words):
        bpy.ops.ellimann.build_reference_set()
    assert state() == before and not (tmp_path / "set").exists()


def test_a_build_is_written_as_a_set_and_loaded_into_a_new_collection(tmp_path, monkeypatch):
    """The Blender side of a build (the core's build is tested in tests/tools): the shipped RMs stand in
    for the build's result."""
    props = _scene_for_build(tmp_path)
    shipped = load_reference_set()
    names = [row.body.name for row in props.bodies]
    base = Mannequin.load(REFERENCE_FOLDER / "base_mannequin.json")

    def build(base_, bodies, targets, progress=None, cancel=None, body_labels=None, **manifest):
        """The core's build without the fitting: the shipped RMs, assembled into a set as the core does (no bodies
        kept: the shipped RMs are not these bodies')."""
        from ellimann_addon.core.fitting.reference_build import BuildReport, BuiltReferenceSet

        rms = {name: rm.copy(name=name) for name, rm in zip(names, shipped.mannequins)}
        report = BuildReport(base=base, reference=names[0])
        report.errors = {name: {"He": 0.0} for name in names}
        return BuiltReferenceSet.assemble(rms, report, targets, **manifest)

    monkeypatch.setattr(operators, "build_reference_set", build)
    monkeypatch.setattr(operators, "validate_inputs", lambda *args: None)
    collections = set(bpy.data.collections)
    assert bpy.ops.ellimann.build_reference_set() == {"FINISHED"}
    new = set(bpy.data.collections) - collections
    assert len(new) == 4  # the set's collection and one per RM
    manifest = read_manifest(tmp_path / "set")
    assert manifest.mannequins == names and manifest.base == "base_mannequin" and manifest.name == "set"
    assert manifest.provenance["built_by"] == "Blender: ElliMann > Build Reference Set"
    assert manifest.provenance["labelled_against"] == names[0]
    assert len(load_reference_set(tmp_path / "set")) == 3
    assert "3 RMs in" in props.status
    # the user's objects are as they were
    assert [body_mesh(row.body).vertices.shape for row in props.bodies] == [(642, 3)] * 3
