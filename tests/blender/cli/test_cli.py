"""The command line: ``main(argv)`` in-process, and ``python -m ellimann_addon`` in a subprocess.

``blender --command ellimann`` needs a Blender binary, which the bpy-module test machines lack; the
add-on registers ``main`` itself as that command (checked below), so the in-process tests cover it.
"""

import csv
import json
import os
import pathlib
import re
import subprocess
import sys

import bpy
import pytest

from devkit import synthetic
from devkit.cli_runs import assert_one_line_error, python_m, run
from ellimann_addon import cli
from ellimann_addon.cli import drape as drape_cli
from ellimann_addon.cli import writing
from ellimann_addon.core.drape.settings import DrapeSettings
from ellimann_addon.core.formats.glb import EXTRAS_KEY, read_glb_json
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ellimann_addon.core.synthesis.synthesize import relative_error

ROOT = pathlib.Path(__file__).resolve().parents[3]
REQUEST = ["--he", "165", "--sh", "41.5", "--br", "101.25", "--wa", "82.75", "--hi", "117.5"]
VALUES = dict(zip(MEASUREMENTS, (165.0, 41.5, 101.25, 82.75, 117.5)))


@pytest.fixture(scope="module")
def references(tmp_path_factory):
    return str(synthetic.write_reference_folder(tmp_path_factory.mktemp("rm")))


# ------------------------------------------------------------------------------------------------ entry points


def five(printed):
    """The five of what ``measure --json`` prints (the extra measurements follow them)."""
    return {key: printed[key] for key in MEASUREMENTS}


def test_python_m_help_is_fast_and_does_not_load_blender():
    code = (
        "import sys\nfrom ellimann_addon.cli import main\ncode = main(['--help'])\n"
        "print('bpy loaded' if 'bpy' in sys.modules else 'bpy not loaded', code)"
    )
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    assert "synth" in out and "batch" in out and "measure" in out and "demo" in out
    assert out.strip().endswith("bpy not loaded 0")


@pytest.mark.parametrize("kind", ["json", "blend"])
def test_python_m_synth_and_measure_end_to_end(tmp_path, references, kind):
    out = tmp_path / f"one.{kind}"
    done = python_m("synth", *REQUEST, "-o", str(out), "--references", references)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(f"wrote {out}") and done.stdout.count("\n") == 1
    measured = python_m("measure", str(out), "--json")
    assert measured.returncode == 0
    data = json.loads(measured.stdout)  # stdout holds the dict and nothing else, even when Blender loads a file
    assert measured.stdout == json.dumps(data) + "\n" and list(data) == list(MEASUREMENTS + EXTRA_MEASUREMENTS)
    assert five(data) == pytest.approx(VALUES, rel=1e-4)


def test_python_m_bad_input_is_one_line_and_exit_code_1(tmp_path, references):
    done = python_m("synth", *REQUEST[:-1], "500", "-o", str(tmp_path / "x.json"), "--references", references)
    assert_one_line_error(done.returncode, done.stderr, "Hi", "30-300 cm")
    assert not (tmp_path / "x.json").exists()


def test_the_add_on_registers_main_as_the_blender_command(monkeypatch):
    from ellimann_addon.blender import cli_command, registry

    # the add-on's register() ran cli_command.register()
    assert (cli_command.register, cli_command.unregister) in registry.HOOKS and cli_command._handle is not None
    calls = []
    monkeypatch.setattr(cli_command, "_handle", None)  # the real handle is restored afterwards
    monkeypatch.setattr(bpy.utils, "register_cli_command", lambda *args: calls.append(("register", args)) or "H")
    monkeypatch.setattr(bpy.utils, "unregister_cli_command", lambda *args: calls.append(("unregister", args)))
    cli_command.register()
    assert calls == [("register", ("ellimann", cli.main))] and cli_command._handle == "H"
    cli_command.unregister()
    assert calls[1:] == [("unregister", ("H",))] and cli_command._handle is None
    cli_command.unregister()  # twice is harmless
    assert len(calls) == 2


def test_a_malformed_command_line_exits_2(capsys):
    code, _, err = run(["synth", "--he", "160"], capsys)
    assert code == 2 and "required" in err
    code, _, err = run(["fly"], capsys)
    assert code == 2


# ------------------------------------------------------------------------------------------------ synth


def test_synth_json_meets_the_request_in_exact_mode(tmp_path, capsys, references):
    out = tmp_path / "sub" / "m.json"
    code, stdout, err = run(["synth", *REQUEST, "-o", str(out), "--references", references], capsys)
    assert code == 0 and err == ""
    mannequin = Mannequin.load(out)
    assert mannequin.name == "ElliMann 165-41.5-101.25-82.75-117.5" and mannequin.measurements == VALUES
    assert mannequin.measure() == pytest.approx(VALUES, rel=1e-4)
    assert "max error 0.00" in stdout


def test_synth_idw_reports_its_error(tmp_path, capsys, references):
    out = tmp_path / "m.json"
    code, stdout, _ = run(
        ["synth", *REQUEST, "--mode", "idw", "--normalize", "none", "-o", str(out), "--references", references], capsys
    )
    assert code == 0
    error = float(stdout.rsplit("max error ", 1)[1].rstrip("%\n"))
    measured = Mannequin.load(out).measure()
    assert error == pytest.approx(relative_error(measured, VALUES).max(), abs=1e-3)
    assert error > 0.1  # the paper's IDW misses: the point of exact mode


@pytest.mark.parametrize(
    "args, words",
    [
        (["--he", "nan"], ("He", "finite")),
        (["--sh", "-3"], ("Sh", "> 0")),
        (["--br", "1000"], ("Br", "30-300 cm")),
        (["--he", "abc"], None),  # argparse: exit 2
    ],
)
def test_synth_refuses_bad_measurements(tmp_path, capsys, references, args, words):
    request = REQUEST.copy()
    index = request.index(args[0])
    request[index + 1] = args[1]
    out = tmp_path / "m.json"
    code, stdout, err = run(["synth", *request, "-o", str(out), "--references", references], capsys)
    if words is None:
        assert code == 2 and "not a number" in err
    else:
        assert_one_line_error(code, err, *words)
    assert not out.exists() and stdout == ""


def test_synth_refuses_unknown_outputs_and_missing_references(tmp_path, capsys, references):
    code, _, err = run(["synth", *REQUEST, "-o", str(tmp_path / "m.stl"), "--references", references], capsys)
    assert_one_line_error(code, err, ".blend, .glb, .obj, .json, .xml (MJCF) or .fbx")
    code, _, err = run(
        ["synth", *REQUEST, "-o", str(tmp_path / "m.json"), "--references", str(tmp_path / "no")], capsys
    )
    assert_one_line_error(code, err, "does not exist")


def test_synth_warns_outside_L(tmp_path, capsys, references):
    request = REQUEST.copy()
    request[1] = "180"
    code, _, err = run(["synth", *request, "-o", str(tmp_path / "m.json"), "--references", references], capsys)
    assert code == 0
    assert err.count("warning: He = 180 cm is outside the reference range 148-171 cm by 9 cm") == 1, err


def test_synth_blender_formats_with_cushions(tmp_path, capsys, references):
    reference = synthetic.make_reference_set()
    pairs = len(reference.topology.cushion_pairs)
    singles = sum(1 for p in reference.topology if not p.partner)
    for kind in ("blend", "glb", "obj"):
        out = tmp_path / f"m.{kind}"
        code, stdout, err = run(["synth", *REQUEST, "--cushions", "-o", str(out), "--references", references], capsys)
        assert code == 0, err
        assert stdout.startswith(f"wrote {out}") and stdout.count("\n") == 1  # Blender's chatter went to stderr
        assert out.stat().st_size > 1000
        assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary left over
    doc = read_glb_json(tmp_path / "m.glb")  # through export_gltf: ElliMann's extras, each convex piece once
    nodes = {n["name"]: n["extras"][EXTRAS_KEY]["kind"] for n in doc["nodes"]}
    assert sorted(nodes.values()) == ["CUSHION"] * pairs + ["ELLIPSOID"] * singles
    assert doc["scenes"][0]["extras"][EXTRAS_KEY]["measured_cm"] == pytest.approx(VALUES, rel=1e-4)
    objects = [line for line in (tmp_path / "m.obj").read_text().splitlines() if line.startswith("o ")]
    assert len(objects) == pairs + singles
    code, stdout, _ = run(["measure", str(tmp_path / "m.blend"), "--json"], capsys)
    assert code == 0 and five(json.loads(stdout)) == pytest.approx(VALUES, rel=1e-4)
    code, stdout, _ = run(["measure", str(tmp_path / "m.glb"), "--json"], capsys)  # the .glb synth wrote: its extras
    assert code == 0 and json.loads(stdout) == pytest.approx(VALUES, rel=1e-4)
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "m.blend"))
    cushions = [o for o in bpy.data.objects if o.ellimann.kind == "CUSHION"]
    assert len(cushions) == pairs
    hidden = [o for o in bpy.data.objects if o.ellimann.kind == "ELLIPSOID" and o.hide_get()]
    assert len(hidden) == 2 * pairs


def test_synth_mjcf_loads_in_mujoco_without_blender(tmp_path, references):
    mujoco = pytest.importorskip("mujoco")
    reference = synthetic.make_reference_set()
    pairs = len(reference.topology.cushion_pairs)
    singles = sum(1 for p in reference.topology if not p.partner)
    out = tmp_path / "m.xml"
    code = (
        "import sys\nfrom ellimann_addon.cli import main\n"
        f"code = main(['synth', *{REQUEST!r}, '--cushions', '-o', {str(out)!r}, '--references', {references!r}])\n"
        "print('bpy loaded' if 'bpy' in sys.modules else 'bpy not loaded', code)"
    )
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.stdout.strip().endswith("bpy not loaded 0"), done.stderr
    model = mujoco.MjModel.from_xml_path(str(out))
    kinds = [int(model.geom_type[i]) for i in range(model.ngeom) if model.geom(i).name != "floor"]
    assert sorted(kinds) == sorted(
        [int(mujoco.mjtGeom.mjGEOM_MESH)] * pairs + [int(mujoco.mjtGeom.mjGEOM_ELLIPSOID)] * singles
    )
    measured = {key: float(model.numeric(f"measured_{key}").data[0]) for key in MEASUREMENTS}
    assert measured == pytest.approx(VALUES, rel=1e-4)


def test_an_unwritable_target_is_named_in_one_line(tmp_path, capsys, references):
    blocker = tmp_path / "a_file"
    blocker.write_text("mine")
    for out in (blocker / "m.json", blocker / "deeper" / "m.blend"):
        code, _, err = run(["synth", *REQUEST, "-o", str(out), "--references", references], capsys)
        assert_one_line_error(code, err, f"cannot write {out}: {blocker} is a file, not a folder")
    (tmp_path / "folder.json").mkdir()
    code, _, err = run(["synth", *REQUEST, "-o", str(tmp_path / "folder.json"), "--references", references], capsys)
    assert_one_line_error(code, err, f"cannot write {tmp_path / 'folder.json'}: it is a folder")
    source = write_csv(tmp_path / "in.csv", GOOD_ROWS[:1])
    code, _, err = run(["batch", source, "-o", str(blocker), "--references", references], capsys)
    assert_one_line_error(code, err, f"cannot write the folder {blocker}: it is a file")
    assert blocker.read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file", "folder.json", "in.csv"]


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs Linux's /proc, where no file can be created")
@pytest.mark.parametrize("kind", ["json", "xml", "blend"])
def test_a_folder_that_takes_no_files_names_the_target_not_the_temporary(capsys, references, kind):
    code, _, err = run(["synth", *REQUEST, "-o", f"/proc/m.{kind}", "--references", references], capsys)
    assert_one_line_error(code, err, f"cannot write /proc/m.{kind}: ")
    assert ".tmp" not in err and ".ellimann-" not in err


# ------------------------------------------------------------------------------------------------ drape


def parse(argv):
    return cli.build_parser().parse_args(argv)


def test_drape_defaults_are_the_drape_settings_defaults():
    """The CLI, the Drape panel and drape() from Python start from DrapeSettings()."""
    args = parse(["drape", "m.json", "-o", "m.blend"])
    assert drape_cli.settings_of(args) == DrapeSettings()
    args = parse(["drape", "m.json", "-o", "m.blend", "--frames", "12", "--edge", "4", "--no-cushions"])
    assert drape_cli.settings_of(args) == DrapeSettings(frames=12, edge=0.04, cushions=False)
    assert drape_cli.settings_of(parse(["drape", "m.json", "-o", "m.blend", "--cushions"])).cushions


def test_drape_help_shows_those_defaults(capsys):
    code, out, _ = run(["drape", "--help"], capsys)
    defaults = DrapeSettings()
    assert code == 0
    help_text = " ".join(out.split())
    assert f"(default {defaults.frames}, at 24 fps)" in help_text
    assert f"(default {defaults.edge * 100:g};" in help_text
    assert f"(default: {'cushions' if defaults.cushions else 'every ellipsoid'})" in help_text


def test_drape_refuses_collection_for_a_json_mannequin(tmp_path, capsys, toy):
    toy.save(tmp_path / "toy.json")
    out = tmp_path / "x.blend"
    code, _, err = run(["drape", str(tmp_path / "toy.json"), "--collection", "Body", "-o", str(out)], capsys)
    assert_one_line_error(code, err, "--collection", "toy.json is a .json file")
    assert not out.exists()


def test_drape_prints_progress_while_it_simulates(tmp_path, capsys, toy):
    toy.save(tmp_path / "toy.json")
    out = tmp_path / "x.blend"
    code, stdout, err = run(
        ["drape", str(tmp_path / "toy.json"), "--frames", "12", "--edge", "6", "--no-cushions", "-o", str(out)], capsys
    )
    assert code == 0, err
    assert stdout.startswith(f"wrote {out}: ")
    lines = [line for line in err.splitlines() if line.startswith("ellimann drape: ")]
    assert lines[0] == "ellimann drape: tube_dress on 'toy', 12 frames, cloth edge 6 cm, colliding with ellipsoids"
    progress = [line.split()[2] for line in lines[1:]]
    assert progress == ["10/12", "12/12"]  # every 10 frames, and the last
    assert lines[-1].endswith("frames simulated; baking and measuring the fit")


# ------------------------------------------------------------------------------------------------ measure


def test_measure_json_prints_exactly_the_dict(tmp_path, capsys, references):
    out = tmp_path / "m.json"
    run(["synth", *REQUEST, "-o", str(out), "--references", references], capsys)
    code, stdout, err = run(["measure", str(out), "--json"], capsys)
    assert code == 0 and err == ""
    data = json.loads(stdout)
    assert stdout == json.dumps(data) + "\n" and list(data) == list(MEASUREMENTS + EXTRA_MEASUREMENTS)
    code, stdout, _ = run(["measure", str(out)], capsys)
    assert code == 0 and "Height" in stdout and "165.00 cm" in stdout


def test_measure_refuses_what_it_cannot_read(tmp_path, capsys):
    code, _, err = run(["measure", str(tmp_path / "none.json")], capsys)
    assert_one_line_error(code, err, "no such file")
    (tmp_path / "bad.json").write_text("{not json")
    code, _, err = run(["measure", str(tmp_path / "bad.json")], capsys)
    assert_one_line_error(code, err, "not valid JSON")
    (tmp_path / "m.txt").write_text("x")
    code, _, err = run(["measure", str(tmp_path / "m.txt")], capsys)
    assert_one_line_error(code, err, ".json, .blend or .glb")
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "empty.blend"))
    code, _, err = run(["measure", str(tmp_path / "empty.blend"), "--json"], capsys)
    assert_one_line_error(code, err, "no ElliMann mannequin")


# ------------------------------------------------------------------------------------------------ batch


def write_csv(path, rows, header=("He", "Sh", "Br", "Wa", "Hi", "name")):
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(header)
        writer.writerows(rows)
    return str(path)


GOOD_ROWS = [
    (159, 43, 117, 104, 117, "average"),
    (153.75, 35.75, 101.25, 102.5, 134.75, "t1"),
    (165.25, 47.25, 135.75, 122.25, 117.5, ""),
]


def read_report(path):
    with open(path, newline="") as stream:
        return list(csv.DictReader(stream))


def test_batch_skips_bad_rows_and_reports_everything(tmp_path, capsys, references):
    rows = (
        GOOD_ROWS[:2]
        + [
            (160, 40, "abc", 90, 100, "bad_number"),
            (500, 40, 100, 90, 100, "absurd"),
            (160, 40, 100, 90, 100, "t1"),
            (160, 40, 100, 90, 100, "no/slash"),
        ]
        + GOOD_ROWS[2:]
    )
    source = write_csv(tmp_path / "in.csv", rows)
    out = tmp_path / "out"
    code, stdout, err = run(
        ["batch", source, "-o", str(out), "--format", "json,blend", "--references", references], capsys
    )
    assert code == 1
    assert "line 4: skipped: Br: 'abc' is not a number" in err
    assert "line 5: skipped: He: 500 cm is not a plausible value" in err
    assert "line 6: skipped: name: 't1' is already used on line 3" in err
    assert "line 7: skipped: name:" in err
    assert "7/7" in err  # progress: every row of the CSV, the refused ones too
    assert "3 of 7 mannequins written" in stdout
    report = read_report(out / "report.csv")
    assert [r["line"] for r in report] == ["2", "3", "4", "5", "6", "7", "8"]
    assert [r["status"] for r in report] == ["ok", "ok", "error", "error", "error", "error", "ok"]
    assert report[-1]["name"] == "row-00007"
    for row in (r for r in report if r["status"] == "ok"):
        mannequin = Mannequin.load(out / f"{row['name']}.json")
        for key in MEASUREMENTS:
            assert float(row[f"{key}_measured"]) == pytest.approx(mannequin.measure()[key], abs=1e-3)
            assert float(row[f"{key}_error_pct"]) < 0.01
        assert (out / f"{row['name']}.blend").is_file()
        assert row["files"].split() == [str(out / f"{row['name']}.json"), str(out / f"{row['name']}.blend")]
    assert not (out / "bad_number.json").exists() and not (out / "absurd.json").exists()


def test_batch_shards_partition_the_rows(tmp_path, capsys, references):
    rows = [(150 + i, 40, 110, 95, 110, f"m{i:02d}") for i in range(10)]
    source = write_csv(tmp_path / "in.csv", rows)
    out = tmp_path / "out"
    seen = []
    for shard in (1, 2, 3):
        code, stdout, _ = run(
            ["batch", source, "-o", str(out), "--shard", f"{shard}/3", "--mode", "idw", "--references", references],
            capsys,
        )
        assert code == 0 and f"shard {shard}/3 of 10 rows" in stdout
        seen.append({r["name"] for r in read_report(out / f"report-{shard}-of-3.csv")})
    assert set().union(*seen) == {r[-1] for r in rows}
    assert sum(len(s) for s in seen) == 10
    assert not (out / "report.csv").exists()


def test_batch_shards_agree_on_duplicate_names_across_the_whole_csv(tmp_path, capsys, references):
    """Rows 1 and 2 share a name but land in different shards: only the first may write DIR/same.json."""
    rows = [
        (150, 40, 110, 95, 110, "same"),
        (160, 40, 110, 95, 110, "same"),
        (155, 40, 110, 95, 110, "SAME"),
        (158, 40, 110, 95, 110, "other"),
    ]
    source = write_csv(tmp_path / "in.csv", rows)
    out = tmp_path / "out"
    errors = {}
    for shard in (1, 2):
        code, _, err = run(
            ["batch", source, "-o", str(out), "--shard", f"{shard}/2", "--mode", "idw", "--references", references],
            capsys,
        )
        assert code == 1  # each shard holds one of the duplicates
        errors[shard] = err
    assert "line 4: skipped: name: 'SAME' is already used on line 2 (as 'same'" in errors[1]
    assert "line 3: skipped: name: 'same' is already used on line 2" in errors[2]
    assert Mannequin.load(out / "same.json").measurements["He"] == 150.0  # not overwritten by line 3
    assert sorted(p.name for p in out.iterdir()) == [
        "made_from",
        "other.json",
        "report-1-of-2.csv",
        "report-2-of-2.csv",
        "same.json",
    ]
    assert sorted(p.name for p in (out / "made_from").iterdir()) == ["other.json", "same.json"]
    assert json.loads((out / "made_from" / "same.json").read_text())["request_cm"]["He"] == 150.0
    statuses = {}
    for shard in (1, 2):
        statuses.update({r["line"]: r["status"] for r in read_report(out / f"report-{shard}-of-2.csv")})
    assert statuses == {"2": "ok", "3": "error", "4": "error", "5": "ok"}


@pytest.mark.parametrize(
    "header, extra, words",
    [
        (("He", "Sh", "Br", "Hi"), [], ("lacks column(s) Wa",)),
        (("He", "Sh", "Br", "Wa", "Hi"), ["--shard", "4/3"], ("--shard must be I/N",)),
        (("He", "Sh", "Br", "Wa", "Hi"), ["--format", "blend,stl"], ("--format",)),
    ],
)
def test_batch_refuses_bad_files_and_options(tmp_path, capsys, references, header, extra, words):
    source = write_csv(tmp_path / "in.csv", [(159, 43, 117, 104, 117)[: len(header)]], header)
    code, _, err = run(["batch", source, "-o", str(tmp_path / "out"), *extra, "--references", references], capsys)
    assert_one_line_error(code, err, *words)
    code, _, err = run(["batch", str(tmp_path / "missing.csv"), "-o", str(tmp_path / "out")], capsys)
    assert_one_line_error(code, err, "missing.csv")


def test_batch_writes_mjcf_and_glb_with_extras(tmp_path, capsys, references):
    source = write_csv(tmp_path / "in.csv", GOOD_ROWS[:1])
    out = tmp_path / "out"
    code, _, err = run(["batch", source, "-o", str(out), "--format", "mjcf,glb", "--references", references], capsys)
    assert code == 0, err
    assert sorted(p.name for p in out.iterdir()) == ["average.glb", "average.xml", "made_from", "report.csv"]
    assert read_report(out / "report.csv")[0]["files"].split() == [str(out / "average.xml"), str(out / "average.glb")]
    assert "<mujoco" in (out / "average.xml").read_text()
    doc = read_glb_json(out / "average.glb")
    assert doc["scenes"][0]["extras"][EXTRAS_KEY]["name"] == "average"
    assert len(doc["nodes"]) == len(synthetic.make_reference_set().topology)


def test_batch_header_is_case_insensitive_and_extra_columns_are_ignored(tmp_path, capsys, references):
    source = write_csv(tmp_path / "in.csv", [(1, 159, 43, 117, 104, 117)], ("id", "he", "SH", "Br", "wa", "Hi"))
    code, _, err = run(["batch", source, "-o", str(tmp_path / "out"), "--references", references], capsys)
    assert code == 0, err
    assert (tmp_path / "out" / "row-00001.json").is_file()


# ------------------------------------------------------------------------------------------------ demo


@pytest.mark.slow
def test_demo_writes_files_report_and_lineup(tmp_path, capsys, references):
    out = tmp_path / "demo"
    code, stdout, err = run(["demo", "-o", str(out), "--references", references], capsys)
    assert code == 0, err
    for i in range(1, 11):
        assert (out / f"table_2_5_{i:02d}.blend").is_file()
        assert Mannequin.load(out / f"table_2_5_{i:02d}.json").measurements is not None
    report = read_report(out / "report.csv")
    assert len(report) == 10 and all(float(r["Br_error_pct"]) < 0.01 for r in report)
    markdown = (out / "report.md").read_text()
    assert "| 10 | 165.25 | 47.25 | 135.75 | 122.25 | 117.5 |" in markdown and "max, paper IDW" in markdown
    assert (out / "lineup.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "10 mannequins" in stdout
    assert "the body's right blue, its left pink, the central pieces grey" in markdown  # the picture's colours said
    from ellimann_addon.blender.bridge.convert import SIDE_COLORS

    (r, _, b, _), (r2, _, b2, _) = SIDE_COLORS["R"], SIDE_COLORS["L"]
    assert b > r and r2 > b2 and abs(SIDE_COLORS["C"][0] - SIDE_COLORS["C"][2]) < 0.1  # and they are those colours


# ------------------------------------------------------------------------------------------------ Blender's chatter

BLENDER_LINES = ("Info:", "INFO", "Writing to", "OBJ export", "EGL", ".ellimann-", "Saved copy", "File exported")


def assert_no_blender_lines(text):
    assert not [line for line in text.splitlines() if any(word in line for word in BLENDER_LINES)], text


def test_synth_glb_prints_only_its_own_line_and_verbose_shows_blender(tmp_path, references):
    out = tmp_path / "m.glb"
    done = python_m("synth", *REQUEST, "-o", str(out), "--references", references)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(f"wrote {out}: ") and done.stdout.count("\n") == 1
    assert done.stderr == ""
    verbose = python_m("synth", *REQUEST, "-o", str(out), "--references", references, "--verbose")
    assert verbose.returncode == 0 and verbose.stdout.count("\n") == 1  # stdout stays ElliMann's
    assert "| INFO: Starting glTF 2.0 export" in verbose.stderr


def test_batch_in_every_blender_format_prints_only_ellimann_lines(tmp_path, references):
    source = write_csv(tmp_path / "in.csv", GOOD_ROWS[:2])
    out = tmp_path / "out"
    done = python_m("batch", source, "-o", str(out), "--format", "blend,glb,obj", "--references", references)
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("\n") == 1 and done.stdout.startswith("ellimann batch: 2 of 2 mannequins written")
    assert all(line.startswith("ellimann batch: ") for line in done.stderr.splitlines()), done.stderr
    assert_no_blender_lines(done.stdout + done.stderr)
    verbose = python_m("batch", source, "-o", str(out), "--format", "blend,glb,obj", "--references", references, "-v")
    assert verbose.returncode == 0 and verbose.stdout == done.stdout
    # Blender 4.x says 'Info: Saved "average.blend"', 5.x 'Info: Saved copy as "average.blend"'.
    assert re.search(r'^Info: Saved (copy as )?"average\.blend"$', verbose.stderr, re.MULTILINE), verbose.stderr
    assert "| INFO: Finished glTF 2.0 export" in verbose.stderr  # (the core writes the .obj: Blender says nothing)


def test_demo_shows_no_blender_output_at_the_file_descriptors(tmp_path, capfd, references):
    """In-process, capfd sees what Blender's C code writes to fds 1 and 2 (Info lines, EGL errors)."""
    code = cli.main(["demo", "-o", str(tmp_path / "demo"), "--references", references])
    out, err = capfd.readouterr()
    assert code == 0, err
    assert out.count("\n") == 1 and out.startswith("ellimann demo: 10 mannequins")
    assert all(line.startswith("ellimann demo: ") for line in err.splitlines()), err


def test_measure_of_a_blend_prints_the_json_alone_at_the_file_descriptors(tmp_path, capfd, references):
    out = tmp_path / "m.blend"
    assert cli.main(["synth", *REQUEST, "-o", str(out), "--references", references]) == 0
    capfd.readouterr()
    assert cli.main(["measure", str(out), "--json"]) == 0
    stdout, stderr = capfd.readouterr()
    assert five(json.loads(stdout)) == pytest.approx(VALUES, rel=1e-4) and stderr == ""


# ------------------------------------------------------------------------------------------------ whole writes

FSIZE_RUN = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails (EFBIG) instead of ending us
from ellimann_addon.blender.services import teardown
from ellimann_addon.cli import main
import os
quiet, stdout = os.open(os.devnull, os.O_WRONLY), os.dup(1)
os.dup2(quiet, 1)  # Blender 5.3 prints its colour configuration on import, which the CLI would have captured
import bpy  # loaded (and Python's caches written) before the limit
os.dup2(stdout, 1)
resource.setrlimit(resource.RLIMIT_FSIZE, ({limit}, {limit}))
teardown.exit_with(main({argv!r}))
"""


@pytest.mark.skipif(not hasattr(os, "setrlimit") and sys.platform == "win32", reason="needs RLIMIT_FSIZE")
@pytest.mark.parametrize("kind", ["blend", "glb", "obj", "json"])
def test_a_write_cut_short_is_one_line_exit_1_and_the_old_file_stays(tmp_path, references, kind):
    """RLIMIT_FSIZE stops every write at 4 KiB, as a full disk does: Blender's .blend writer returns normally
    from a cut-short file, the glTF exporter and the core (.obj, .json) raise; each ends in one line."""
    pytest.importorskip("resource")
    out = tmp_path / f"m.{kind}"
    out.write_bytes(b"the user's")
    argv = ["synth", *REQUEST, "-o", str(out), "--references", references]
    done = subprocess.run(
        [sys.executable, "-c", FSIZE_RUN.format(limit=4096, argv=argv)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert_one_line_error(done.returncode, done.stderr, f"cannot write {out}: ")
    assert done.stdout == "" and ".ellimann-" not in done.stderr
    assert any(words in done.stderr for words in ("incomplete", "File too large")), done.stderr
    assert out.read_bytes() == b"the user's"
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"m.{kind}"]


@pytest.mark.skipif(not (hasattr(os, "geteuid") and os.geteuid() == 0), reason="mounting a tmpfs needs root")
def test_a_full_disk_is_caught_on_a_64k_tmpfs(tmp_path, references):
    full = tmp_path / "full"
    full.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(full)], capture_output=True).returncode:
        pytest.skip("cannot mount a tmpfs here")
    try:
        for kind in ("blend", "obj"):
            done = python_m("synth", *REQUEST, "-o", str(full / f"m.{kind}"), "--references", references)
            assert_one_line_error(
                done.returncode, done.stderr, f"cannot write {full / f'm.{kind}'}: ", "No space left on device"
            )
            assert not list(full.iterdir())
    finally:
        subprocess.run(["umount", str(full)], check=True)


@pytest.mark.parametrize("kind", ["blend", "glb", "obj", "json"])
def test_a_name_too_long_for_the_file_system_is_one_line(tmp_path, capsys, references, kind):
    out = tmp_path / ("a" * 300 + f".{kind}")
    code, stdout, err = run(["synth", *REQUEST, "-o", str(out), "--references", references], capsys)
    assert_one_line_error(code, err, f"cannot write {out}: ", "File name too long")
    assert stdout == "" and ".ellimann-" not in err and not list(tmp_path.iterdir())


def test_blender_write_errors_become_one_line_os_errors():
    from ellimann_addon.core.files import blender_write_error

    temp, target = "/out/.ellimann-1@h-abcdefgh/m.glb", "out/m.glb"
    gltf = RuntimeError(
        'Error: Python: Traceback (most recent call last):\n  File "x.py", line 85, in save_gltf\n'
        f"OSError: [Errno 28] No space left on device: '{temp}'\nLocation: ops.py:109\n"
    )
    error = blender_write_error(gltf, temp, target)
    assert (error.errno, error.strerror, error.filename) == (28, "No space left on device", target)
    blend = RuntimeError(f"Error: Cannot open file {temp}@ for writing: File name too long\n")
    assert blender_write_error(blend, temp, target).strerror == "File name too long"
    other = blender_write_error(RuntimeError(f"Error: OBJ Export: Cannot open file '{temp}'\n"), "/tmp", target)
    assert other.filename == target and temp not in other.strerror  # the probe names the real reason


# ------------------------------------------------------------------------------------------------ batch: failures


def test_a_batch_row_blender_fails_to_write_is_reported_and_the_batch_goes_on(
    tmp_path, capsys, references, monkeypatch
):
    from ellimann_addon.blender.services import files

    real = files.export_gltf

    def full_disk_for_t1(collection, path, *given):
        if os.path.basename(path) == "t1.glb":
            with files.atomic_output(path) as temp:  # what a bpy.ops call raises when the disk is full
                raise RuntimeError(
                    f"Error: Python: Traceback (most recent call last):\nOSError: [Errno 28] No "
                    f"space left on device: '{temp}'\nLocation: ops.py:109\n"
                )
        return real(collection, path, *given)

    monkeypatch.setattr(files, "export_gltf", full_disk_for_t1)
    source = write_csv(tmp_path / "in.csv", GOOD_ROWS)
    out = tmp_path / "out"
    code, stdout, err = run(
        ["batch", source, "-o", str(out), "--format", "json,glb", "--references", references], capsys
    )
    assert code == 1 and "Traceback" not in err
    assert f"line 3: failed: cannot write {out / 't1.glb'}: No space left on device" in err
    assert "2 of 3 mannequins written" in stdout
    assert [r["status"] for r in read_report(out / "report.csv")] == ["ok", "error", "ok"]
    assert (out / "row-00003.glb").is_file() and not (out / "t1.glb").exists()
    assert not [p for p in out.iterdir() if p.name.startswith(".") or "partial" in p.name]


def test_ctrl_c_in_a_batch_writes_the_report_of_what_was_done_and_exits_130(tmp_path, capsys, references, monkeypatch):
    real, calls = writing.write, []

    def interrupted_on_the_second_row(*args, **keywords):
        calls.append(args)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*args, **keywords)

    monkeypatch.setattr(writing, "write", interrupted_on_the_second_row)
    source = write_csv(tmp_path / "in.csv", GOOD_ROWS + [(160, 40, "abc", 90, 100, "bad")])
    out = tmp_path / "out"
    code, stdout, err = run(["batch", source, "-o", str(out), "--references", references], capsys)
    assert code == 130 and stdout == ""
    assert err.strip().splitlines()[-1] == (
        f"ellimann batch: interrupted: 1 of 4 rows done, report "
        f"{out / 'report.csv'}; run it again with --resume to finish"
    )
    assert [(r["line"], r["status"]) for r in read_report(out / "report.csv")] == [("2", "ok"), ("5", "error")]
    assert sorted(p.name for p in out.iterdir()) == ["average.json", "made_from", "report.csv"]
    first = (out / "average.json").stat()
    monkeypatch.setattr(writing, "write", real)
    code, stdout, err = run(["batch", source, "-o", str(out), "--resume", "--references", references], capsys)
    assert code == 1 and "3 of 4 mannequins written" in stdout and "(1 already complete, kept)" in stdout
    assert (out / "average.json").stat().st_ino == first.st_ino  # kept, not written again
    report = read_report(out / "report.csv")
    assert [r["status"] for r in report] == ["ok", "ok", "ok", "error"] and "kept (--resume)" in report[0]["message"]


KILLED_RUN = """
import os, signal, sys, tempfile
from ellimann_addon.cli import writing, main
from ellimann_addon.core.files import temp_prefix
real, calls = writing.write, []
def killed_on_the_third_row(result, formats, *args, **keywords):
    calls.append(list(formats))
    if len(calls) == 3:  # killed while writing: a temporary is on disk
        tempfile.mkstemp(prefix=temp_prefix(), suffix=".tmp", dir=os.path.dirname(calls[-1][0]))
        os.kill(os.getpid(), signal.SIGKILL)
    return real(result, formats, *args, **keywords)
writing.write = killed_on_the_third_row
from ellimann_addon.blender.services import teardown
teardown.exit_with(main({argv!r}))
"""


@pytest.mark.skipif(os.name != "posix", reason="SIGKILL")
def test_a_killed_batch_leaves_a_partial_report_and_resume_cleans_up_and_finishes(tmp_path, references):
    rows = [(150 + i, 40, 110, 95, 110, f"m{i}") for i in range(5)]
    source = write_csv(tmp_path / "in.csv", rows)
    out = tmp_path / "out"
    argv = ["batch", source, "-o", str(out), "--references", references]
    done = subprocess.run(
        [sys.executable, "-c", KILLED_RUN.format(argv=argv)], cwd=ROOT, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == -9
    assert [r["name"] for r in read_report(out / "report.partial.csv")] == ["m0", "m1"]
    assert len([p for p in out.iterdir() if p.name.startswith(".ellimann-")]) == 1
    (out / "m1.json").write_text((out / "m1.json").read_text()[:100])  # and a file cut short
    kept = (out / "m0.json").stat().st_ino
    again = python_m(*argv, "--resume")
    assert again.returncode == 0, again.stderr
    assert f"removed 1 temporary file(s) an interrupted run left in {out}" in again.stderr
    assert "5 of 5 mannequins written" in again.stdout and "(1 already complete, kept)" in again.stdout
    assert (out / "m0.json").stat().st_ino == kept
    assert Mannequin.load(out / "m1.json").measurements["He"] == 151.0  # written again, whole
    assert sorted(p.name for p in out.iterdir()) == [f"m{i}.json" for i in range(5)] + ["made_from", "report.csv"]
    assert [r["status"] for r in read_report(out / "report.csv")] == ["ok"] * 5


def test_batch_without_resume_writes_every_row_again(tmp_path, capsys, references):
    source = write_csv(tmp_path / "in.csv", GOOD_ROWS[:1])
    out = tmp_path / "out"
    assert run(["batch", source, "-o", str(out), "--references", references], capsys)[0] == 0
    first = (out / "average.json").stat().st_ino
    code, stdout, _ = run(["batch", source, "-o", str(out), "--references", references], capsys)
    assert code == 0 and "kept" not in stdout and (out / "average.json").stat().st_ino != first


# ------------------------------------------------------------------------------------------------ untrusted text


def test_names_from_a_csv_cannot_become_formulas_or_terminal_escapes(tmp_path, capsys, references):
    rows = [
        (159, 43, 117, 104, 117, name)
        for name in ('=HYPERLINK("http://evil","x")', "+1+2", "-2+3", "@SUM(A1)", "\x1b[2J\x1b[31mred", "ok\u202eevil")
    ]
    source = write_csv(tmp_path / "in.csv", rows + [GOOD_ROWS[1]])
    out = tmp_path / "out"
    code, _, err = run(["batch", source, "-o", str(out), "--references", references], capsys)
    assert code == 1
    assert "\x1b" not in err and "\u202e" not in err and "\\x1b[2J" in err
    text = (out / "report.csv").read_text()
    assert "\x1b" not in text and "\u202e" not in text
    report = read_report(out / "report.csv")
    assert [r["name"][:2] for r in report[:4]] == ["'=", "'+", "'-", "'@"]
    assert report[4]["name"] == "\\x1b[2J\\x1b[31mred" and report[5]["name"] == "ok\\u202eevil"
    assert report[6]["status"] == "ok" and report[6]["name"] == "t1"


def test_text_from_the_command_line_and_files_is_printed_without_control_characters(tmp_path, capsys, references):
    out = tmp_path / "m.json"
    code, stdout, _ = run(
        ["synth", *REQUEST, "--name", "\x1b]0;owned\x07\rx", "-o", str(out), "--references", references], capsys
    )
    assert code == 0 and "\x1b" not in stdout and "\\x1b]0;owned\\x07\\rx" in stdout
    code, stdout, _ = run(["measure", str(out)], capsys)
    assert code == 0 and "\x1b" not in stdout and stdout.startswith("\\x1b]0;owned")


# ------------------------------------------------------------------------------------------------ exact mode misses

ABSURD = ["--he", "50", "--sh", "10", "--br", "300", "--wa", "300", "--hi", "300"]  # plausible alone, not together


def test_exact_mode_missing_a_request_warns_naming_it_and_exits_3(tmp_path, capsys, references):
    out = tmp_path / "m.json"
    code, stdout, err = run(["synth", *ABSURD, "-o", str(out), "--references", references], capsys)
    assert code == cli.MISSED == 3
    warning = [line for line in err.splitlines() if "exact mode missed" in line]
    assert len(warning) == 1 and "Sh by 18.6" in warning[0] and "(m_T " in warning[0]
    assert "tolerance 0.001%" in warning[0]
    assert stdout.startswith(f"wrote {out}") and out.is_file()  # the closest mannequin, written
    code, _, err = run(["synth", *ABSURD, "--mode", "idw", "-o", str(out), "--references", references], capsys)
    assert code == 0 and "missed" not in err  # IDW promises no match
    source = write_csv(tmp_path / "in.csv", [GOOD_ROWS[0], (50, 10, 300, 300, 300, "absurd")])
    code, _, err = run(["batch", source, "-o", str(tmp_path / "out"), "--references", references], capsys)
    assert code == 3 and "line 3: warning: exact mode missed" in err
    assert [r["status"] for r in read_report(tmp_path / "out" / "report.csv")] == ["ok", "missed"]


def test_writing_a_glb_registers_the_properties_it_needs_and_no_panel(tmp_path):
    """``synth -o x.glb`` under ``python -m`` registers ElliMann's object and collection properties (what the
    writers read), not the add-on's panels and operators (which register the Blender command, which imports the
    command line again)."""
    code = (
        "import sys\nfrom ellimann_addon.cli import main\n"
        f"code = main(['synth', '--he', '165', '--sh', '41.5', '--br', '101.25', '--wa', '82.75', '--hi', '117.5', "
        f"'-o', {str(tmp_path / 'x.glb')!r}, '-q'])\n"
        "import bpy\n"
        "print(code, hasattr(bpy.types.Collection, 'ellimann'), "
        "sorted(n for n in dir(bpy.types) if n.startswith(('ELLIMANN_PT', 'ELLIMANN_OT'))))\n"
        "from ellimann_addon.blender.services import teardown\nteardown.exit_with(0)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.stdout.strip().splitlines()[-1] == "0 True []", done.stdout + done.stderr
    assert (tmp_path / "x.glb").is_file()
