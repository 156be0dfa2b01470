"""The fine sets in Blender: the panel's "Female, fine" and "Male, fine" synthesize from them, with cushions built
by the operator as the core builds them; the mannequin measures, rigs and exports; a live update onto a mannequin
of the other topology is refused in one line, nothing moved; the command line and a batch row choose them by name."""

import csv

import bpy
import numpy as np
import pytest

from devkit.blender_scene import state
from devkit.cli_runs import run
from ellimann_addon.blender.bridge import convert
from ellimann_addon.blender.bridge.built import built_objects
from ellimann_addon.blender.bridge.convert import world_triangles
from ellimann_addon.blender.features.synthesize.live import live_update
from ellimann_addon.core.formats.glb import EXTRAS_KEY, read_glb_json
from ellimann_addon.core.geometry import mesh
from ellimann_addon.core.geometry.cushion import cushion_mesh
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.shipped import named_reference_set

REQUESTS = {
    "FEMALE_FINE": ("female-fine", dict(He=162.0, Sh=40.0, Br=104.0, Wa=88.0, Hi=106.0)),
    "MALE_FINE": ("male-fine", dict(He=180.0, Sh=52.0, Br=108.0, Wa=96.0, Hi=104.0)),
}


def synthesize(choice, output="CUSHIONS"):
    props = bpy.context.scene.ellimann_synthesis
    props.live = False
    props.reference_set, props.output, props.mode = choice, output, "EXACT"
    for key, value in REQUESTS[choice][1].items():
        setattr(props, key.lower(), value)
    assert bpy.ops.ellimann.synthesize_mannequin() == {"FINISHED"}
    return props.target


def convex_halves(obj, vertices, faces):
    """[(vertices, faces)] of each convex piece of a cushion object: the whole mesh, or the two halves, one per
    bone's vertex group, of a cushion the rig cut at a joint (blender.services.rig.bind_across)."""
    if len(obj.vertex_groups) < 2:
        return [(vertices, faces)]
    owner = np.array([max(v.groups, key=lambda g: g.weight).group for v in obj.data.vertices])
    halves = []
    for group in np.unique(owner):
        kept = faces[owner[faces[:, 0]] == group]
        used = np.unique(kept)
        halves.append((vertices[used], np.searchsorted(used, kept)))
    return halves


@pytest.mark.parametrize("choice, export", [("FEMALE_FINE", True), ("MALE_FINE", False)])  # one topology: one export
def test_the_panel_synthesizes_from_a_fine_set_with_its_cushions_and_exports(choice, export, tmp_path):
    name, request = REQUESTS[choice]
    reference = named_reference_set(name)
    coarse = named_reference_set(name.removesuffix("-fine")).topology
    collection = synthesize(choice)
    mannequin = convert.collection_to_mannequin(collection)
    assert collection.ellimann.reference_set == name and len(mannequin) == len(reference.topology)
    assert convert.rig_object(collection) is not None  # rigged: every part of the fine topology on a bone
    built = {o.ellimann.part_name: o for o in built_objects(collection, "CUSHION")}
    assert len(built) == len(reference.topology.cushion_pairs)
    for i, j in mannequin.topology.cushion_pairs:
        if mannequin.topology.names[i] in coarse.index and mannequin.topology.names[j] in coarse.index:
            continue  # the 40's cushions: tests/blender/features/test_cushions_measure.py, services/test_rig.py
        first, second = ((mannequin.rotation[k], mannequin.center[k], mannequin.semi_axes[k]) for k in (i, j))
        obj = built[mannequin.topology.names[i]]
        vertices, faces = world_triangles(obj)
        for half_vertices, half_faces in convex_halves(obj, vertices, faces):
            assert mesh.is_closed_manifold(half_faces) and mesh.convexity_defect(half_vertices, half_faces) < 1e-5
        core_vertices, core_faces = cushion_mesh(first, second, round(np.log2((len(vertices) - 2) / 10) / 2))
        assert mesh.volume(vertices, faces) == pytest.approx(mesh.volume(core_vertices, core_faces), rel=1e-4)
    bpy.context.view_layer.objects.active = next(o for o in collection.objects if o.ellimann.kind == "ELLIPSOID")
    assert bpy.ops.ellimann.measure_mannequin(source="ELLIPSOIDS") == {"FINISHED"}
    assert tuple(collection.ellimann.measured) == pytest.approx(tuple(request.values()), rel=1e-4)
    if not export:
        return
    path = tmp_path / "fine.glb"
    assert bpy.ops.ellimann.export_mannequin(filepath=str(path)) == {"FINISHED"}
    nodes = read_glb_json(path)["nodes"]
    extras = [node.get("extras", {}).get(EXTRAS_KEY, {}) for node in nodes]
    extras = [e for e in extras if "part" in e]  # the pieces (the armature's node may carry other extras)
    exported = {e["part"] for e in extras} | {e["partner"] for e in extras if e["kind"] == "CUSHION"}
    assert exported == set(reference.topology.names)  # every part, alone or in its cushion


def test_a_live_update_onto_a_mannequin_of_the_other_topology_is_refused_in_one_line():
    props = bpy.context.scene.ellimann_synthesis
    synthesize("FEMALE_FINE", output="ELLIPSOIDS")
    props.reference_set = "FEMALE"  # the 40: the live target holds the fine topology's pieces
    before = state()
    props.live = True  # a live update now
    assert "another topology" in props.status and "\n" not in props.status
    assert live_update(bpy.context.scene) is None and state() == before
    props.live = False


def test_the_command_line_and_a_batch_row_choose_a_fine_set_by_name(tmp_path, capsys):
    table = tmp_path / "rows.csv"
    table.write_text(
        "name,He,Sh,Br,Wa,Hi,references\nfine,162,40,104,88,106,female-fine\npaper,162,40,104,88,106,\n",
        encoding="utf-8",
    )
    code, _, err = run(["batch", str(table), "-o", str(tmp_path / "out")], capsys)
    assert code == 0, err
    with open(tmp_path / "out" / "report.csv", encoding="utf-8") as stream:
        rows = {row["name"]: row for row in csv.DictReader(stream)}
    assert (rows["fine"]["references"], rows["paper"]["references"]) == ("female-fine", "female")
    sizes = {name: len(Mannequin.load(tmp_path / "out" / f"{name}.json")) for name in rows}
    assert sizes == {"fine": len(named_reference_set("female-fine").topology), "paper": 40}
    for name in rows:
        assert max(abs(float(rows[name][f"{k}_error_pct"])) for k in MEASUREMENTS) < 1e-3
