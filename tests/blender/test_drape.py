"""Draping with Blender cloth, headless: short, coarse simulations on the A-pose toy.

Each drape here simulates a few frames of a coarse garment (4 cm edges); what is checked is what a
short run can show: the cloth falls, pins hold, seams close, nothing ends inside the body, the file
replays the bake. Figures on real bodies are in bench/bench_drape.py.
"""

import bpy
import numpy as np
import pytest

from devkit.blender_scene import parts, select, state
from devkit.poses import make_apose_toy
from devkit.ui_recorder import draw_panel
from ellimann_addon.blender import cli, drape_panel, ids
from ellimann_addon.blender.convert import mannequin_to_collection
from ellimann_addon.blender.drape import CLOTH_NAME, PIN_GROUP, DrapeSettings, drape, evaluated_vertices
from ellimann_addon.core.errors import ElliMannError

COARSE = {"edge": 0.04}
PENETRATION_TOLERANCE = 0.01  # fraction of garment vertices allowed inside the exact pieces
DEPTH_TOLERANCE = 0.008  # m: the colliders are inscribed polyhedra, and cloth collisions are soft


@pytest.fixture(scope="module")
def body():
    return make_apose_toy()


def assert_outside(fit):
    assert fit["penetrating_fraction"] <= PENETRATION_TOLERANCE, fit
    assert fit["max_depth"] <= DEPTH_TOLERANCE, fit


def test_tube_dress_falls_on_the_ellipsoids_held_by_its_pins(body):
    collection = mannequin_to_collection(body)
    before = state()
    result = drape(body, "tube_dress", DrapeSettings(frames=12, cushions=False, **COARSE))
    garment, obj = result.garment, result.garment_object
    moved = result.vertices - garment.vertices
    hem = garment.vertices[:, 2] < garment.vertices[:, 2].min() + 1e-6
    # Hung from its pins, the dress only stretches a little (the pinned top edge stays); the cloth's
    # collision distance also pushes it off the body a little. Gravity is what pulls the hem down.
    assert moved[hem, 2].mean() < 0.0
    assert np.abs(moved[garment.pins]).max() < 0.002
    assert_outside(result.fit)
    # What was built: the garment with its cloth and pin group, one hidden collider per ellipsoid.
    assert obj.name in result.collection.objects and len(result.collection.children) == 1
    colliders = result.collection.children[0]
    cloth = obj.modifiers[CLOTH_NAME]
    assert cloth.settings.vertex_group_mass == PIN_GROUP
    assert sorted(v.index for v in obj.data.vertices if v.groups) == sorted(garment.pins.tolist())
    assert cloth.collision_settings.collection == colliders
    assert len(colliders.objects) == len(body) and result.collider_triangles == len(body) * 320
    assert all(o.modifiers[0].type == "COLLISION" and o.hide_get() and o.hide_render for o in colliders.objects)
    assert cloth.point_cache.is_baked and bpy.context.scene.frame_current == 12
    assert len(result.seconds) == len(result.cpu_seconds) == 11
    # The mannequin is not touched.
    after = state()
    assert {k: after["objects"][k] for k in before["objects"]} == before["objects"]
    assert parts(collection)["1.a Head"].modifiers.get("Collision") is None
    bpy.context.scene.use_gravity = False
    weightless = drape(body, "tube_dress", DrapeSettings(frames=12, cushions=False, **COARSE))
    assert (weightless.vertices - garment.vertices)[hem, 2].mean() > moved[hem, 2].mean() + 0.002


def test_t_shirt_seams_close_on_the_cushions(body):
    result = drape(body, "t_shirt", DrapeSettings(frames=16, cushions=True, **COARSE))
    garment = result.garment
    assert len(result.pieces) == len(body) - len(body.topology.cushion_pairs)
    before = np.linalg.norm(garment.vertices[garment.seams[:, 0]] - garment.vertices[garment.seams[:, 1]], axis=1)
    after = result.seam_gaps()
    assert np.median(after) < 0.3 * np.median(before)
    mesh = result.garment_object.data
    loose = {tuple(sorted(e.vertices)) for e in mesh.edges if e.is_loose}
    assert loose == {tuple(sorted(s)) for s in garment.seams.tolist()}  # the sewing springs
    assert result.garment_object.modifiers[CLOTH_NAME].settings.use_sewing_springs
    assert_outside(result.fit)


def test_bad_settings_and_garments_change_nothing(body):
    mannequin_to_collection(body)
    before = state()
    for settings, words in ((DrapeSettings(frames=1), "frames: must be an integer from 2"),
                            (DrapeSettings(edge=0.0), "edge"),
                            (DrapeSettings(sphere_subdivisions=9), "sphere_subdivisions")):
        with pytest.raises(ElliMannError, match=words):
            drape(body, "tube_dress", settings)
    with pytest.raises(ElliMannError, match="garment: must be one of"):
        drape(body, "skirt", DrapeSettings(**COARSE))
    assert state() == before


# ------------------------------------------------------------------------------------------------ operator, panel


def test_operator_drapes_the_active_mannequin_and_reports(body):
    collection = mannequin_to_collection(body)
    select(parts(collection)["2.a Chest"])
    props = bpy.context.scene.ellimann_drape
    props.frames, props.edge, props.cushions = 8, 0.05, True
    assert bpy.ops.ellimann.drape_garment() == {"FINISHED"}
    drapes = [c for c in bpy.data.collections if c.name.startswith("Drape Tube dress on")]
    assert len(drapes) == 1 and "8 frames" in props.status and "inside the body" in props.status
    recorder = draw_panel(drape_panel.ELLIMANN_PT_drape)
    assert recorder.operators() == [ids.DRAPE_GARMENT]
    assert {"garment", "frames", "edge", "cushions"} <= set(recorder.props())
    assert any("8 frames" in label for label in recorder.labels())


def test_drape_panel_draws_in_an_empty_file():
    recorder = draw_panel(drape_panel.ELLIMANN_PT_drape)
    assert recorder.operators() == [ids.DRAPE_GARMENT] and recorder.labels() == []
    assert drape_panel.ELLIMANN_PT_drape.bl_parent_id == ids.PANEL_MAIN and drape_panel.ELLIMANN_PT_drape.bl_order == 70


def test_operator_refuses_a_broken_mannequin_and_needs_one(body):
    assert not bpy.ops.ellimann.drape_garment.poll()
    collection = mannequin_to_collection(body)
    thigh = parts(collection)["6.a Thigh.L"]
    thigh.scale.x *= -1
    select(thigh)
    bpy.context.view_layer.update()
    before = state()
    with pytest.raises(RuntimeError, match="Fix 'toy \\(A-pose\\)' first: '6.a Thigh.L'"):
        bpy.ops.ellimann.drape_garment()
    assert state() == before


# ------------------------------------------------------------------------------------------------ CLI


def run(args, capsys):
    code = cli.main(args)
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_drapes_a_json_mannequin_into_a_blend_and_a_picture(body, tmp_path, capsys):
    source = tmp_path / "body.json"
    body.save(source)
    out, picture = tmp_path / "out" / "dress.blend", tmp_path / "out" / "dress.png"
    code, stdout, err = run(["drape", str(source), "--frames", "6", "--edge", "5", "-o", str(out),
                             "--render", str(picture)], capsys)
    assert code == 0, err
    assert stdout.splitlines()[0].startswith(f"wrote {out}: Tube dress on 'toy (A-pose)', 6 frames")
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in out.parent.iterdir()) == ["dress.blend", "dress.png"]  # no temporaries
    bpy.ops.wm.open_mainfile(filepath=str(out))
    obj = bpy.data.objects["Tube dress"]
    assert obj.modifiers[CLOTH_NAME].point_cache.is_baked and bpy.context.scene.frame_current == 6
    rest = np.array([v.co[:] for v in obj.data.vertices])
    assert np.linalg.norm(evaluated_vertices(obj) - rest, axis=1).max() > 1e-3  # it replays the drape


def test_cli_drapes_a_mannequin_in_a_blend(body, tmp_path, capsys):
    mannequin_to_collection(body, name="Body")
    mannequin_to_collection(body, name="Other")
    source = tmp_path / "two.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source))
    out = tmp_path / "draped.blend"
    code, _, err = run(["drape", str(source), "--frames", "4", "--edge", "5", "-o", str(out)], capsys)
    assert code == 1 and "choose one with --collection" in err and not out.exists()
    code, stdout, err = run(["drape", str(source), "--collection", "Body", "--frames", "4", "--edge", "5",
                             "--garment", "t_shirt", "-o", str(out)], capsys)
    assert code == 0, err
    assert "T-shirt on 'Body'" in stdout and out.is_file()


@pytest.mark.parametrize("args, words", [
    (["-o", "x.obj"], "-o must end in .blend"),
    (["-o", "x.blend", "--render", "x.jpg"], "--render must end in .png"),
    (["-o", "x.blend", "--frames", "1"], "frames: must be an integer from 2 to 2000"),
    (["-o", "x.blend", "--edge", "0"], "edge"),
])
def test_cli_refuses_bad_options(body, tmp_path, capsys, args, words):
    source = tmp_path / "body.json"
    body.save(source)
    args = [tmp_path / a if a.startswith("x.") else a for a in args]
    code, _, err = run(["drape", str(source), *map(str, args)], capsys)
    assert code == 1 and len(err.strip().splitlines()) == 1 and words in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["body.json"]


def test_cli_refuses_bad_mannequins(tmp_path, capsys):
    out = str(tmp_path / "x.blend")
    code, _, err = run(["drape", str(tmp_path / "none.json"), "-o", out], capsys)
    assert code == 1 and "no such file" in err
    (tmp_path / "body.obj").write_text("v 0 0 0\n")
    code, _, err = run(["drape", str(tmp_path / "body.obj"), "-o", out], capsys)
    assert code == 1 and ".json or .blend" in err
    make_apose_toy().copy(name="toy").save(tmp_path / "toy.json")
    code, _, err = run(["drape", str(tmp_path / "toy.json"), "--garment", "skirt", "-o", out], capsys)
    assert code == 2 and "invalid choice" in err
    assert not (tmp_path / "x.blend").exists()
