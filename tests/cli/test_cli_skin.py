"""``--skin`` on the command line: its options come from the SKIN table; the .obj holds the skin alone (one closed
mesh, Y up, rest or posed) and ``measure`` of it agrees with what synth reports; the .json records how the skin was
made and ``pose IN.json --skin`` makes the same skin again; MJCF draws it (MuJoCo moves it with the bones exactly as
``Skin.posed`` does); ``batch --skin`` reports the skin beside the pieces; exact mode meets the request on the skin;
the skin reaches Blender's writers; every bad input is refused in one line before any work, nothing written.

Skins are made at the preview level (10 mm) where the assertion allows it."""

import argparse
import contextlib
import csv
import io
import json
import os
import types

import numpy as np
import pytest

from devkit.cli_runs import assert_one_line_error, run
from ellimann_addon.cli import build_parser, main, skin_options
from ellimann_addon.core.geometry.mesh import euler_characteristic, is_closed_manifold
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.skin_record import SkinSettings
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.pose.standard import standard_pose
from ellimann_addon.core.settings import LEVELS, SKIN
from ellimann_addon.core.skin.exact import MESH_TOLERANCE_CM
from ellimann_addon.core.skin.measure import mesh_measurements
from ellimann_addon.core.skin.surface import build_skin

REQUEST = ["--he", "165", "--sh", "41.5", "--br", "101.25", "--wa", "82.75", "--hi", "117.5"]
ASKED = dict(zip(MEASUREMENTS, (165.0, 41.5, 101.25, 82.75, 117.5)))
PREVIEW = ["--skin", "--skin-level", "preview"]


def quiet_main(argv):
    """cli.main in this process outside a test's capsys (module fixtures): (code, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def obj_mesh(path):
    """(objects, vertices (V, 3) as written, faces (F, 3) 0-based) of an .obj."""
    lines = path.read_text().splitlines()
    vertices = np.array([line.split()[1:] for line in lines if line.startswith("v ")], dtype=float)
    faces = np.array([line.split()[1:] for line in lines if line.startswith("f ")], dtype=np.int64) - 1
    return [line[2:] for line in lines if line.startswith("o ")], vertices, faces


@pytest.fixture(scope="module")
def idw(tmp_path_factory):
    """synth --skin (preview, IDW) to .json (its --json result kept) and to .obj."""
    folder = tmp_path_factory.mktemp("skin")
    code, stdout, stderr = quiet_main(
        ["synth", *REQUEST, *PREVIEW, "--mode", "idw", "-o", str(folder / "w.json"), "--json"]
    )
    assert code == 0, stderr
    code, line, stderr = quiet_main(["synth", *REQUEST, *PREVIEW, "--mode", "idw", "-o", str(folder / "w.obj")])
    assert code == 0, stderr
    return types.SimpleNamespace(folder=folder, result=json.loads(stdout), line=line)


# ------------------------------------------------------------------------------------------------ options


@pytest.mark.parametrize("command", ["synth", "batch", "pose"])
def test_the_skin_options_are_generated_from_the_skin_table(command):
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices[command]
    flags = {option: action for action in sub._actions for option in action.option_strings}
    assert "--skin" in flags
    for name, option in SKIN.items():
        action = flags["--" + name.replace("_", "-")]
        assert action.default is None  # unset: the file's record or the table's default decides
        assert tuple(action.choices or ()) == option.values
        low, high = SKIN["skin_voxel"].limits
        assert action.help == option.help.format(default=option.default, low=low, high=high)


def settings_of(recorded=None, **given):
    args = argparse.Namespace(skin=True, **{name: given.get(name) for name in SKIN})
    return skin_options.skin_settings(args, recorded)


def test_a_skin_option_wins_over_the_file_s_record_which_wins_over_the_table():
    recorded = SkinSettings(7.5, 0.9).to_dict()
    default = SkinSettings(LEVELS[SKIN["skin_level"].default], SKIN["skin_blend"].default, SKIN["skin_kind"].default)
    assert settings_of() == default and default.kind == "auto"  # the body skin where the set has bodies
    assert settings_of(skin_level="preview").kind == "pieces"  # a setting of the pieces' skin asks for it
    assert settings_of(recorded) == SkinSettings(7.5, 0.9)
    assert settings_of(recorded, skin_level="preview") == SkinSettings(10.0, 0.9)
    assert settings_of(recorded, skin_level="preview", skin_voxel=6.0, skin_blend=0.3) == SkinSettings(6.0, 0.3)
    assert skin_options.skin_settings(argparse.Namespace(skin=False, **dict.fromkeys(SKIN)), recorded) is None


# ------------------------------------------------------------------------------------------------ bad input

BAD = [
    (["synth", *REQUEST, "--skin-voxel", "10", "-o", "{tmp}/x.json"], ["--skin-voxel is a setting of the skin"]),
    (["synth", *REQUEST, "--skin-level", "preview", "-o", "{tmp}/x.obj"], ["--skin-level", "add --skin"]),
    (["synth", *REQUEST, "--skin", "--skin-voxel", "0.2", "-o", "{tmp}/x.obj"], ["--skin-voxel: must be", "1 to 40"]),
    (["synth", *REQUEST, "--skin", "--skin-voxel", "nan", "-o", "{tmp}/x.obj"], ["--skin-voxel: must be"]),
    (["synth", *REQUEST, "--skin", "--skin-blend", "5", "-o", "{tmp}/x.obj"], ["--skin-blend: must be", "0 to 3"]),
    (["synth", *REQUEST, "--skin", "--skin-voxel", "1", "-o", "{tmp}/x.obj"], ["--skin-voxel: 1 mm", "GB", "fits"]),
    (["synth", *REQUEST, "--skin", "--skin-voxel", "20", "-o", "{tmp}/x.obj"], ["Fingers", "too thin for 20 mm"]),
    (["batch", "{tmp}/in.csv", "-o", "{tmp}/out", "--skin", "--format", "json,npz"], ["--format npz", "pieces only"]),
    (["batch", "{tmp}/in.csv", "-o", "{tmp}/out", "--skin", "--dask", "local:1"], ["--skin with --dask"]),
    (["batch", "{tmp}/in.csv", "-o", "{tmp}/out", "--skin", "--skin-voxel", "30"], ["Hand.L", "too thin"]),
    (["batch", "{tmp}/in.csv", "-o", "{tmp}/out", "--skin-blend", "1"], ["--skin-blend is a setting"]),
    (["pose", "{tmp}/nojoints.json", "--pose", "sit", "--skin", "-o", "{tmp}/x.obj"], ["has no joints", "skin"]),
    (["pose", "{tmp}/badskin.json", "--pose", "sit", "--skin", "-o", "{tmp}/x.obj"], ["skin.voxel_mm", "1 to 40"]),
    (["pose", "{tmp}/rest.json", "--pose", "sit", "--skin-voxel", "5", "-o", "{tmp}/x.obj"], ["add --skin"]),
]


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("inputs")
    (folder / "in.csv").write_text("He,Sh,Br,Wa,Hi,name\n160,40,95,80,105,a\n", encoding="utf-8")
    assert quiet_main(["synth", *REQUEST, "-o", str(folder / "rest.json")])[0] == 0
    data = json.loads((folder / "rest.json").read_text())
    (folder / "nojoints.json").write_text(json.dumps({k: v for k, v in data.items() if k != "joints"}))
    (folder / "badskin.json").write_text(json.dumps({**data, "skin": {**SkinSettings().to_dict(), "voxel_mm": 0.5}}))
    return folder


@pytest.mark.parametrize("argv, words", BAD)
def test_bad_skin_input_is_refused_in_one_line_before_any_work(tmp_path, inputs, capsys, argv, words):
    for name in ("in.csv", "rest.json", "nojoints.json", "badskin.json"):
        (tmp_path / name).write_bytes((inputs / name).read_bytes())
    before = sorted(p.name for p in tmp_path.iterdir())
    code, stdout, stderr = run([a.format(tmp=tmp_path) for a in argv], capsys)
    assert_one_line_error(code, stderr, *words)
    assert stdout == "" and sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written, no folder made


def test_a_body_s_extra_measurements_are_kept_in_exact_mode_on_the_skin(idw, tmp_path, capsys):
    """synth --from BODY --skin in exact mode keeps the body's extra measurements (the skin meets them too): no
    line about them; the voxel refused next shows the request got that far, nothing written."""
    body = idw.folder / "w.obj"
    code, stdout, stderr = run(
        ["synth", "--from", str(body), "--skin", "--skin-voxel", "20", "-o", str(tmp_path / "x.obj")], capsys
    )
    (error,) = stderr.strip().splitlines()
    assert code == 1 and error.startswith("ellimann synth: error: --skin-voxel: ") and "too thin for 20 mm" in error
    assert not list(tmp_path.iterdir())


def test_exact_mode_meets_an_extra_measurement_on_the_skin(tmp_path, capsys):
    """--neck with --skin in exact mode: the skin's mesh measures the five and the neck asked within 1 mm (the
    pieces' neck left below it: the blend adds the rest), reported in --json and in no warning."""
    out = tmp_path / "n.obj"
    code, stdout, stderr = run(
        ["synth", *REQUEST, "--neck", "27", "--skin", "--skin-level", "preview", "--json", "-o", str(out)], capsys
    )
    assert code == 0, stderr
    result = json.loads(stdout)
    asked = {**dict(zip(MEASUREMENTS, map(float, REQUEST[1::2]))), "neck": 27.0}
    for key, wanted in asked.items():
        assert abs(result["skin"]["measured"][key] - wanted) <= MESH_TOLERANCE_CM, key
    assert result["skin"]["exact"] and result["skin"]["converged"]
    assert result["measured"]["neck"] < 27.0 - MESH_TOLERANCE_CM


# ------------------------------------------------------------------------------------------------ files


def test_the_obj_holds_the_skin_alone_one_closed_mesh_standing_y_up(idw):
    objects, vertices, faces = obj_mesh(idw.folder / "w.obj")
    assert objects == ["ElliMann 165-41.5-101.25-82.75-117.5 skin"]
    assert is_closed_manifold(faces) and euler_characteristic(vertices, faces) == 2
    extent = np.ptp(vertices, axis=0)
    assert extent[1] == pytest.approx(1.65, abs=0.01) and abs(vertices[:, 1].min()) < 0.005  # Y up, feet at y = 0
    assert len(vertices) == idw.result["skin"]["vertices"] and len(faces) == idw.result["skin"]["faces"]
    assert "skin 10 mm), skin He 164.9" in idw.line and "; pieces' m_T He 164.9" in idw.line


def test_measure_of_the_skin_s_obj_agrees_with_what_synth_reported(idw, capsys):
    """The body-mesh measurer on the file (OBJ axes, 9 digits) against the skin's measurements synth reported (the
    skin's own mesh measurer): the same definitions on the same mesh."""
    code, stdout, stderr = run(["measure", str(idw.folder / "w.obj"), "--json"], capsys)
    assert code == 0, stderr
    measured, reported = json.loads(stdout), idw.result["skin"]["measured"]
    for key in MEASUREMENTS:
        assert measured[key] == pytest.approx(reported[key], abs=2e-4), key  # measure --json rounds to 1e-4 cm
    pieces = idw.result["measured"]
    assert any(abs(reported[key] - pieces[key]) > 0.5 for key in MEASUREMENTS)  # the skin is not the pieces


def test_in_idw_a_body_s_extra_measurements_are_measured_on_the_skin_beside_the_pieces(idw, tmp_path, capsys):
    body = idw.folder / "w.obj"
    argv = ["synth", "--from", str(body), *PREVIEW, "--mode", "idw", "-o", str(tmp_path / "t.json"), "--json"]
    code, stdout, stderr = run(argv, capsys)
    assert code == 0 and stderr.startswith(f"{body}: measured He "), stderr  # --json: stdout holds the JSON alone
    result = json.loads(stdout)
    skin, pieces = result["skin"]["measured"], result["measured"]
    assert (
        list(skin)
        == list(pieces)
        == [*MEASUREMENTS, "neck", "upper_arm", "thigh", "calf", "crotch_height", "arm_length"]
    )
    assert all(isinstance(skin[key], float) for key in skin)
    assert skin["thigh"] - pieces["thigh"] > 0.5  # the skin over the thigh's pieces


def test_the_json_records_how_the_skin_was_made_and_pose_makes_the_same_skin_again(idw, tmp_path, capsys):
    mannequin = Mannequin.load(idw.folder / "w.json")
    assert mannequin.skin == SkinSettings(10.0).to_dict()
    assert idw.result["skin"]["voxel_mm"] == 10.0 and idw.result["skin"]["version"] == 1
    code, stdout, stderr = run(
        ["pose", str(idw.folder / "w.json"), "--pose", "a_pose", "--skin", "-o", str(tmp_path / "a.obj")], capsys
    )
    assert code == 0 and stdout.endswith("in pose a_pose, with its skin 10 mm\n"), stderr
    rest = obj_mesh(idw.folder / "w.obj")
    again = obj_mesh(tmp_path / "a.obj")
    assert np.array_equal(again[2], rest[2]) and np.allclose(again[1], rest[1], atol=1e-9)  # a_pose is rest
    code, _, _ = run(
        ["pose", str(idw.folder / "w.json"), "--pose", "sit", "--skin", "-o", str(tmp_path / "s.obj")], capsys
    )
    skin = build_skin(mannequin, SkinSettings(10.0))
    posed = skin.posed(standard_pose("sit", mannequin.joints))
    _, vertices, faces = obj_mesh(tmp_path / "s.obj")
    assert code == 0 and np.array_equal(faces, skin.faces)
    assert np.allclose(vertices, np.c_[posed[:, 0], posed[:, 2], -posed[:, 1]], atol=1e-8)  # Y up
    assert np.abs(vertices - rest[1]).max() > 0.2  # the knees and feet moved


def test_mjcf_draws_the_skin_and_mujoco_moves_it_with_the_bones_as_skin_posed_does(idw, tmp_path, capsys):
    mujoco = pytest.importorskip("mujoco")
    mannequin = Mannequin.load(idw.folder / "w.json")
    skin = build_skin(mannequin, SkinSettings(10.0))
    code, _, stderr = run(["synth", *REQUEST, *PREVIEW, "--mode", "idw", "-o", str(tmp_path / "w.xml")], capsys)
    assert code == 0, stderr
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "w.xml"))
    assert model.nskin == 1 and model.ngeom == 41  # the floor and the 40 pieces: the skin is no geom
    assert np.allclose(skin_vertices(mujoco, model), skin.vertices, atol=2e-6)  # float32
    code, _, stderr = run(
        ["pose", str(idw.folder / "w.json"), "--pose", "sit", "--skin", "-o", str(tmp_path / "p.xml")], capsys
    )
    assert code == 0, stderr
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "p.xml"))
    posed = skin.posed(standard_pose("sit", mannequin.joints))
    assert np.allclose(skin_vertices(mujoco, model, key=0), posed, atol=2e-6)
    assert np.abs(posed - skin.vertices).max() > 0.2


def skin_vertices(mujoco, model, key=None):
    """The skin's vertices as MuJoCo's visualiser places them (at a keyframe, if given)."""
    data = mujoco.MjData(model)
    if key is not None:
        mujoco.mj_resetDataKeyframe(model, data, key)
    mujoco.mj_forward(model, data)
    scene = mujoco.MjvScene(model, maxgeom=100)
    mujoco.mjv_updateScene(
        model, data, mujoco.MjvOption(), mujoco.MjvPerturb(), mujoco.MjvCamera(), mujoco.mjtCatBit.mjCAT_ALL, scene
    )
    return np.array(scene.skinvert).reshape(-1, 3)


def test_batch_reports_each_row_s_skin_beside_its_pieces_and_resume_keeps_the_files(tmp_path, capsys):
    source = tmp_path / "in.csv"
    source.write_text("He,Sh,Br,Wa,Hi,name\n160,40,95,80,105,a\n170,42,100,85,110,b\n", encoding="utf-8")
    argv = ["batch", str(source), "-o", str(tmp_path / "out"), "--format", "obj,json", *PREVIEW, "--mode", "idw"]
    code, _, stderr = run(argv, capsys)
    assert code == 0, stderr
    rows = list(csv.DictReader((tmp_path / "out" / "report.csv").open(encoding="utf-8")))
    for row in rows:
        assert row["status"] == "ok" and row["skin_voxel_mm"] == "10" and row["skin_blend"] == "0.6"
        code, stdout, _ = run(["measure", str(tmp_path / "out" / f"{row['name']}.obj"), "--json"], capsys)
        on_file = json.loads(stdout)
        for key in MEASUREMENTS:
            assert float(row[f"{key}_skin"]) == pytest.approx(on_file[key], abs=2e-4), key
            asked = float(row[key])
            assert float(row[f"{key}_skin_error_pct"]) == pytest.approx(
                abs(on_file[key] - asked) / asked * 100, abs=1e-3
            )
        assert Mannequin.load(tmp_path / "out" / f"{row['name']}.json").skin == SkinSettings(10.0).to_dict()
    assert any(float(r["Hi_skin"]) - float(r["Hi_measured"]) > 1.0 for r in rows)  # the blend fills the thighs' gap
    code, stdout, stderr = run([*argv, "--resume"], capsys)
    assert code == 0 and "(2 already complete, kept)" in stdout, stderr
    kept = list(csv.DictReader((tmp_path / "out" / "report.csv").open(encoding="utf-8")))
    assert [r["message"] for r in kept] == ["kept (--resume)"] * 2 and kept[0]["He_skin"] == ""
    # resumed with another skin, or with none before: each row is written again, never kept without its skin
    coarser = [*argv[: argv.index("--skin-level")], "--skin-voxel", "12", "--mode", "idw", "--resume"]
    code, stdout, stderr = run(coarser, capsys)
    assert code == 0 and "(2 already complete" not in stdout, stderr
    assert Mannequin.load(tmp_path / "out" / "a.json").skin == SkinSettings(12.0).to_dict()
    plain = tmp_path / "plain"
    assert run(["batch", str(source), "-o", str(plain), "--format", "obj,json", "--mode", "idw"], capsys)[0] == 0
    code, stdout, stderr = run(
        ["batch", str(source), "-o", str(plain), "--format", "obj,json", *PREVIEW, "--resume"], capsys
    )
    assert code == 0 and "(2 already complete" not in stdout, stderr
    assert "mm voxels" in (plain / "a.obj").read_text(encoding="utf-8").splitlines()[0]


@pytest.mark.slow
def test_exact_mode_meets_the_request_on_the_skin_and_measure_of_its_obj_agrees(tmp_path, capsys):
    """Final level (5 mm): the skin's mesh within 1 mm of each of the five, the pieces' m_T beside it (less: the blend
    adds what the pieces lack), and the body-mesh measurer on the .obj agreeing."""
    out = tmp_path / "e.obj"
    code, stdout, stderr = run(["synth", *REQUEST, "--skin", "--skin-kind", "pieces", "-o", str(out), "--json"], capsys)
    assert code == 0, stderr
    result = json.loads(stdout)
    skin = result["skin"]
    assert skin["exact"] and skin["converged"] and skin["voxel_mm"] == 5.0 and skin["rounds"] >= 1
    for key in MEASUREMENTS:
        assert abs(skin["measured"][key] - ASKED[key]) <= MESH_TOLERANCE_CM, key
    assert ASKED["Br"] - result["measured"]["Br"] > 0.5 and ASKED["Hi"] - result["measured"]["Hi"] > 0.5
    code, stdout, _ = run(["measure", str(out), "--json"], capsys)
    on_file = json.loads(stdout)
    for key in MEASUREMENTS:
        assert on_file[key] == pytest.approx(skin["measured"][key], abs=2e-4), key


# ------------------------------------------------------------------------------------------------ Blender's writers


def test_the_skin_is_passed_down_to_blender_s_writers(tmp_path, monkeypatch):
    """.blend/.glb go to the format table's Blender rows (their writer bound by blender.services.writers) with the
    skin and the frames, both paths in one call (one scene); here the writer is a stand-in that records its calls."""
    from ellimann_addon.cli import writing
    from ellimann_addon.core.formats import table
    from ellimann_addon.core.job.result import Result, SkinMade
    from ellimann_addon.core.synthesis.shipped import named_reference_set

    calls = []

    def stand_in(mannequin, paths, *, skin=None, frames=None, **_):
        calls.append(("posed" if frames else "rest", skin, [os.path.basename(path) for path in paths]))

    for name in table.BLENDER_FORMATS:
        monkeypatch.setattr(table.FORMATS[name], "write", stand_in)
    monkeypatch.setattr(writing, "blender_writers", lambda what="": None)
    mannequin = named_reference_set("female").mannequins[4]
    skin = build_skin(mannequin, SkinSettings(10.0))
    result = Result(mannequin, mannequin.measure(), skin=SkinMade(skin, {}, False))
    writing.write(result, table.check_outputs([tmp_path / "a.glb", tmp_path / "a.blend"]))
    result.frames, result.fps = [standard_pose("sit", mannequin.joints)], 24
    writing.write(result, table.check_outputs([tmp_path / "a.blend"]))
    assert calls == [("rest", skin, ["a.glb", "a.blend"]), ("posed", skin, ["a.blend"])]
    assert mesh_measurements(skin)["He"] > 150.0
