"""Draping with Blender cloth, headless: short, coarse simulations on the A-pose toy.

Each drape here simulates a few frames of a coarse garment (4 cm edges); what is checked is what a
short run can show: the cloth falls, pins hold, seams close, nothing ends inside the body, the file
replays the bake. Figures on real bodies are in bench/bench_drape.py.
"""

import contextlib

import bpy
import numpy as np
import pytest

from devkit.blender_scene import parts, select, state
from devkit.poses import make_apose_toy
from devkit.ui_recorder import draw_panel
from ellimann_addon import cli
from ellimann_addon.blender import ids
from ellimann_addon.blender.bridge.convert import mannequin_to_collection
from ellimann_addon.blender.features.drape import operator as drape_operator
from ellimann_addon.blender.features.drape import panel as drape_panel
from ellimann_addon.blender.services import drape as drape_module
from ellimann_addon.blender.services.drape import CLOTH_NAME, PIN_GROUP, DrapeSettings, drape, evaluated_vertices
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
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 3, 7  # the user's range, shorter than the drape: left alone
    before = state()
    frames_done = []
    result = drape(body, "tube_dress", DrapeSettings(frames=12, cushions=False, **COARSE), progress=frames_done.append)
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
    assert cloth.point_cache.is_baked and (cloth.point_cache.frame_start, cloth.point_cache.frame_end) == (1, 12)
    assert (scene.frame_start, scene.frame_end, scene.frame_current) == (3, 7, 12)
    assert len(result.seconds) == len(result.cpu_seconds) == 11 and result.frames == 12
    assert frames_done == list(range(1, 13))
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
    for settings, words in (
        (DrapeSettings(frames=1), "frames: must be an integer from 2"),
        (DrapeSettings(edge=0.0), "edge"),
        (DrapeSettings(sphere_subdivisions=9), "sphere_subdivisions"),
    ):
        with pytest.raises(ElliMannError, match=words):
            drape(body, "tube_dress", settings)
    with pytest.raises(ElliMannError, match="garment: must be one of"):
        drape(body, "skirt", DrapeSettings(**COARSE))
    assert state() == before


def failing_bake(scene, obj, frames, progress=None):
    """A bake that gets a frame in and then fails as Blender's operators do, with a RuntimeError."""
    scene.frame_set(2)
    progress(1)
    raise RuntimeError("Operator bpy.ops.ptcache.bake_from_cache.poll() failed, context is incorrect")


def test_a_blender_error_while_simulating_removes_the_drape(body, monkeypatch):
    mannequin_to_collection(body)
    bpy.context.scene.frame_set(5)
    before = state()
    monkeypatch.setattr(drape_module, "bake", failing_bake)
    with pytest.raises(ElliMannError, match="Blender failed while simulating the drape: Operator bpy.ops.ptcache"):
        drape(body, "tube_dress", DrapeSettings(frames=4, cushions=False, **COARSE), progress=lambda _: None)
    assert state() == before


def test_a_blender_error_while_building_removes_the_drape(body, monkeypatch):
    mannequin_to_collection(body)
    before = state()
    build = drape_module.collider_objects

    def failing_colliders(pieces, collection):
        build(pieces[:2], collection)
        raise RuntimeError("Error: Not enough memory")

    monkeypatch.setattr(drape_module, "collider_objects", failing_colliders)
    with pytest.raises(ElliMannError, match="Blender failed while building the drape: Error: Not enough memory"):
        drape(body, "tube_dress", DrapeSettings(frames=4, cushions=False, **COARSE))
    assert state() == before


def test_any_error_while_building_removes_what_was_made_even_a_mesh_no_object_uses_yet(body, monkeypatch):
    mannequin_to_collection(body)
    before = state()
    made = []
    real = drape_module.mesh_from_arrays

    def failing_mesh(name, vertices, faces):
        mesh = real(name, vertices, faces)
        made.append(name)
        if name.startswith("Collider"):  # the garment is linked; this mesh exists but no object uses it
            raise ValueError("not a Blender error")
        return mesh

    monkeypatch.setattr(drape_module, "mesh_from_arrays", failing_mesh)
    with pytest.raises(ValueError, match="not a Blender error"):  # not a RuntimeError: it goes on as it is
        drape(body, "tube_dress", DrapeSettings(frames=4, cushions=False, **COARSE))
    assert len(made) == 2 and made[1].startswith("Collider")
    assert state() == before


def test_an_error_while_measuring_the_fit_removes_the_drape(body, monkeypatch):
    mannequin_to_collection(body)
    bpy.context.scene.frame_set(5)
    before = state()

    def failing_fit(distance):
        raise FloatingPointError("fit failed")

    monkeypatch.setattr(drape_module, "fit_statistics", failing_fit)
    with pytest.raises(FloatingPointError, match="fit failed"):
        drape(body, "tube_dress", DrapeSettings(frames=3, cushions=False, **COARSE))
    assert state() == before  # the drape's objects, meshes and collections gone; back on frame 5


# ------------------------------------------------------------------------------------------------ operator, panel


class FakeWindowManager:
    def __init__(self):
        self.calls = []

    def progress_begin(self, low, high):
        self.calls.append(("begin", low, high))

    def progress_update(self, value):
        self.calls.append(value)

    def progress_end(self):
        self.calls.append("end")


def test_progress_bar_ends_however_the_work_ends():
    window_manager = FakeWindowManager()
    with pytest.raises(ValueError), drape_operator.progress_bar(window_manager, 3) as update:
        update(1)
        raise ValueError("stopped")
    assert window_manager.calls == [("begin", 0, 3), 1, "end"]


@pytest.fixture
def progress_log(monkeypatch):
    """What the operator shows on Blender's progress indicator (which it still drives)."""
    log = []
    real = drape_operator.progress_bar

    @contextlib.contextmanager
    def recording(window_manager, total):
        assert window_manager == bpy.context.window_manager
        log.append(("begin", total))
        try:
            with real(window_manager, total) as update:
                yield lambda frame: (log.append(frame), update(frame))
        finally:
            log.append("end")

    monkeypatch.setattr(drape_operator, "progress_bar", recording)
    return log


def test_operator_drapes_the_active_mannequin_and_reports(body, progress_log, capfd):
    collection = mannequin_to_collection(body)
    select(parts(collection)["2.a Chest"])
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 5, 30
    props = scene.ellimann_drape
    props.frames, props.edge, props.cushions = 8, 0.05, True
    assert bpy.ops.ellimann.drape_garment() == {"FINISHED"}
    drapes = [c for c in bpy.data.collections if c.name.startswith("Drape Tube dress on")]
    assert len(drapes) == 1 and "8 frames" in props.status and "inside the body" in props.status
    assert "Info: Baked 8 frames (" in capfd.readouterr().out
    assert progress_log == [("begin", 8), *range(1, 9), "end"]
    assert (scene.frame_start, scene.frame_end, scene.frame_current) == (5, 30, 8)
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


def test_operator_reports_a_blender_error_and_leaves_the_file_as_it_was(body, monkeypatch, progress_log):
    collection = mannequin_to_collection(body)
    select(parts(collection)["2.a Chest"])
    props = bpy.context.scene.ellimann_drape
    props.frames, props.edge, props.cushions = 4, 0.05, False
    before = state()
    monkeypatch.setattr(drape_module, "bake", failing_bake)
    with pytest.raises(RuntimeError) as caught:
        bpy.ops.ellimann.drape_garment()
    message = str(caught.value)
    assert "Cannot drape 'toy (A-pose)': Blender failed while simulating the drape" in message
    assert "Traceback" not in message  # a report, not a Python error
    assert progress_log == [("begin", 4), 1, "end"]
    assert state() == before and props.status == ""


# ------------------------------------------------------------------------------------------------ CLI


def run(args, capsys):
    code = cli.main(args)
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_drapes_a_json_mannequin_into_a_blend_and_a_picture(body, tmp_path, capsys):
    source = tmp_path / "body.json"
    body.save(source)
    out, picture = tmp_path / "out" / "dress.blend", tmp_path / "out" / "dress.png"
    code, stdout, err = run(
        ["drape", str(source), "--frames", "6", "--edge", "5", "-o", str(out), "--render", str(picture)], capsys
    )
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
    code, stdout, err = run(
        [
            "drape",
            str(source),
            "--collection",
            "Body",
            "--frames",
            "4",
            "--edge",
            "5",
            "--garment",
            "t_shirt",
            "-o",
            str(out),
        ],
        capsys,
    )
    assert code == 0, err
    assert "T-shirt on 'Body'" in stdout and out.is_file()


@pytest.mark.parametrize(
    "args, words",
    [
        (["-o", "x.obj"], "-o must end in .blend"),
        (["-o", "x.blend", "--render", "x.jpg"], "--render must end in .png"),
        (["-o", "x.blend", "--frames", "1"], "frames: must be an integer from 2 to 2000"),
        (["-o", "x.blend", "--edge", "0"], "edge"),
    ],
)
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
