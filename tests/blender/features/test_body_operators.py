"""Measure Body Mesh and Synthesize from Mesh on a mesh object, headless; the panel's extra measurements."""

import json

import bpy
import numpy as np
import pytest

from devkit.blender_scene import state
from devkit.toy import make_toy_mannequin
from ellimann_addon.blender.features.measure.body import RESULT_PROPERTY
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry.mesh import icosphere
from ellimann_addon.core.measure.body import measure_body_mesh
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS
from tools.shipped.reference_sets import TRACING_FOLDER


def body_object(vertices, faces, name="scan"):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(np.asarray(vertices).tolist(), [], np.asarray(faces).tolist())
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    return obj


def toy_mesh():
    toy = make_toy_mannequin()
    unit, faces = icosphere(3)
    vertices = [(unit * a) @ r.T + c for r, c, a in zip(toy.rotation, toy.center, toy.semi_axes)]
    return np.concatenate(vertices), np.concatenate([faces + i * len(unit) for i in range(len(vertices))])


def test_measure_body_mesh_stores_what_the_core_measures():
    vertices, faces = toy_mesh()
    obj = body_object(vertices, faces)
    obj.location.x = 0.5  # measured in world space, where it stands
    bpy.context.view_layer.update()
    assert bpy.ops.ellimann.measure_body() == {"FINISHED"}
    stored = json.loads(obj[RESULT_PROPERTY])
    expected = measure_body_mesh(vertices + [0.5, 0.0, 0.0], faces).values
    # Blender keeps vertices in float32 (to ~0.1 um here): the same numbers within 10 um
    assert stored == pytest.approx(expected, abs=1e-3)


def test_measure_body_mesh_refuses_a_lying_body_and_changes_nothing():
    vertices, faces = toy_mesh()
    body_object(vertices[:, [2, 1, 0]], faces)
    before = state()
    with pytest.raises(RuntimeError, match="the body lies down .*: turn it to stand along Z; nothing measured"):
        bpy.ops.ellimann.measure_body()
    assert state() == before and RESULT_PROPERTY not in bpy.context.active_object


def test_poll_wants_a_mesh_outside_any_mannequin(toy_collection):
    assert not bpy.ops.ellimann.measure_body.poll()  # the active object is a mannequin's ellipsoid
    assert not bpy.ops.ellimann.synthesize_from_mesh.poll()


def test_synthesize_from_mesh_makes_a_twin_in_a_new_collection():
    """The panel's default set (female) and the average reference body: the twin meets its five."""
    average = read_obj(TRACING_FOLDER / "average.obj", up="z")
    body_object(average.vertices, average.faces, "average")
    collections = set(bpy.data.collections)
    assert bpy.ops.ellimann.synthesize_from_mesh() == {"FINISHED"}
    (twin,) = set(bpy.data.collections) - collections
    assert twin.ellimann.is_mannequin
    measured = dict(zip(("He", "Sh", "Br", "Wa", "Hi"), twin.ellimann.measured))
    assert measured["He"] == pytest.approx(159.00, abs=0.01) and measured["Hi"] == pytest.approx(117.00, abs=0.01)


def test_panel_offers_every_extra_measurement():
    props = bpy.context.scene.ellimann_synthesis
    for key in EXTRA_MEASUREMENTS:
        assert getattr(props, f"use_{key}") is False and getattr(props, key) > 0.0


@pytest.mark.slow
def test_a_mannequins_exported_obj_measures_as_the_mannequin(tmp_path, capsys):
    """The OBJ (Y up) of a synthesized mannequin, measured as a body mesh with the mannequin's neck tilt (its
    joints'): its m_T and the extra measurements within ISO 20685's allowances (the pieces are level-3
    icospheres, inscribed: girths read a little short). Measured blind, the neck is taken where a tape drawn
    tight settles on the pieces, nearer level than the joints (the traced neck piece stands vertical): less, by
    1.6 cm here."""
    from devkit.cli_runs import run
    from ellimann_addon.core.mannequin.model import Mannequin
    from ellimann_addon.core.measure.extra import mannequin_tilt
    from ellimann_addon.core.measurements import ISO_ALLOWANCE

    request = ["--he", "160", "--sh", "42", "--br", "100", "--wa", "80", "--hi", "100"]
    for kind in ("json", "obj"):
        code, _, err = run(["synth", *request, "-o", str(tmp_path / f"m.{kind}")], capsys)
        assert code == 0, err
    closed_form = json.loads(run(["measure", str(tmp_path / "m.json"), "--json"], capsys)[1])
    tilt = np.degrees(mannequin_tilt(Mannequin.load(tmp_path / "m.json")))
    code, out, err = run(["measure", str(tmp_path / "m.obj"), "--json", f"--neck-tilt={float(tilt)!r}"], capsys)
    assert code == 0, err
    mesh = json.loads(out)
    assert set(mesh) == set(closed_form)
    for key, value in closed_form.items():
        assert mesh[key] == pytest.approx(value, abs=ISO_ALLOWANCE[key]), key
    blind = json.loads(run(["measure", str(tmp_path / "m.obj"), "--json"], capsys)[1])["neck"]
    assert closed_form["neck"] - 2.0 < blind < closed_form["neck"]


def test_the_twin_stands_beside_the_body_in_one_piece():
    """Every piece and the armature move together (children with their parents): the twin keeps its width."""
    from ellimann_addon.blender.bridge.convert import collection_to_mannequin

    average = read_obj(TRACING_FOLDER / "average.obj", up="z")
    body_object(average.vertices, average.faces, "average")
    collections = set(bpy.data.collections)
    bpy.ops.ellimann.synthesize_from_mesh()
    (twin,) = set(bpy.data.collections) - collections
    placed = collection_to_mannequin(twin)
    width = np.ptp(average.vertices[:, 0])
    assert placed.center[:, 0].min() > average.vertices[:, 0].max()  # beside the body, not inside it
    assert np.ptp(placed.center[:, 0]) < width  # not pulled apart
