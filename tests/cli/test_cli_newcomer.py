"""What a newcomer trips on, each tried as they would: a misspelt batch column, rows with more cells than the header,
``batch --format xml`` (synth's extension), ``references build --output`` (every command's) with ``--out`` kept,
``--version``, the measure table's columns, ``-0.0000%``, ``references check`` of a shipped set by name, ``measure``
of a .json with a skin (its pieces and its skin, labelled) and of a .glb (its extras), and a file too large to be a
mannequin refused before it is read."""

import csv
import json
import os
import re
import struct
import tomllib

import pytest

from devkit.cli_runs import ROOT, assert_one_line_error, run
from ellimann_addon import VERSION
from ellimann_addon.cli import build_parser
from ellimann_addon.core.files import MAX_READ_BYTES
from ellimann_addon.core.formats.glb import EXTRAS_FORMAT, EXTRAS_KEY, EXTRAS_VERSION
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

REQUEST = ["--he", "165", "--sh", "41.5", "--br", "101.25", "--wa", "82.75", "--hi", "117.5"]
FIVE = {"He": 165.0, "Sh": 41.5, "Br": 101.25, "Wa": 82.75, "Hi": 117.5}


def test_a_misspelt_column_is_named_before_any_work(tmp_path, capsys):
    source = tmp_path / "in.csv"
    source.write_text("name,He,Sh,Br,Wa,Hi,thight\nx,165,41.5,101.25,82.75,117.5,60\n", encoding="utf-8")
    out = tmp_path / "out"
    code, _, err = run(["batch", str(source), "-o", str(out)], capsys)
    assert_one_line_error(code, err, "'thight'", "did you mean thigh?", "He,Sh,Br,Wa,Hi", "arm_length")
    assert not out.exists()  # nothing made


def test_other_unknown_columns_and_overfull_rows_are_said_before_any_row(tmp_path, capsys):
    source = tmp_path / "in.csv"
    source.write_text(
        "name,He,Sh,Br,Wa,Hi,notes,\n"  # a trailing comma: an untitled column no row fills is no column
        "a,165,41.5,101.25,82.75,117.5,tall,\n"
        "b,165,41.5,101.25,82.75,117.5,x,,1,2\n"  # cells past the header: a comma that needed quotes
        "c,165,41.5,101.25,82.75,117.5,,,,\n",  # empty cells past it: a spreadsheet's padding
        encoding="utf-8",
    )
    code, _, err = run(["batch", str(source), "-o", str(tmp_path / "out"), "-q"], capsys)
    assert code == 1
    lines = err.strip().splitlines()
    assert "warning:" in lines[0] and "column(s) notes are not read" in lines[0] and "crotch_height" in lines[0]
    assert "1 row(s) have more cells than the header's 8 (line 3): refused" in lines[1]
    rows = list(csv.DictReader((tmp_path / "out" / "report.csv").open(encoding="utf-8")))
    assert [(r["name"], r["status"]) for r in rows] == [("a", "ok"), ("b", "error"), ("c", "ok")]
    assert rows[1]["message"].startswith("row: has 10 cells, the header 8")


def test_population_s_extra_columns_are_named_as_not_read(tmp_path, capsys):
    people = tmp_path / "people.csv"
    assert (
        run(
            ["population", "--stats", "ansur2_female", "--n", "2", "--seed", "1", "--extras", "-o", str(people)], capsys
        )[0]
        == 0
    )
    code, _, err = run(["batch", str(people), "-o", str(tmp_path / "out"), "-q", "--mode", "idw"], capsys)
    assert code == 0 and "column(s) neck_base, biceps_flexed, biacromial are not read" in err


@pytest.mark.parametrize("spelling", ["xml", "mjcf", ".xml", "XML"])
def test_batch_format_takes_synth_s_xml_as_mjcf(tmp_path, capsys, spelling):
    source = tmp_path / "in.csv"
    source.write_text("name,He,Sh,Br,Wa,Hi\nx,165,41.5,101.25,82.75,117.5\n", encoding="utf-8")
    code, _, err = run(["batch", str(source), "-o", str(tmp_path / "out"), "--format", f"{spelling},json"], capsys)
    assert code == 0, err
    assert (tmp_path / "out" / "x.xml").is_file() and (tmp_path / "out" / "x.json").is_file()


def test_references_build_takes_output_as_every_command_and_still_out():
    parser = build_parser()
    base = ["references", "build", "--base", "b.json", "--bodies", "a.obj", "b.obj", "c.obj", "--targets", "t.csv"]
    for flag in ("-o", "--output", "--out"):
        assert parser.parse_args([*base, flag, "DIR"]).output == "DIR"
    build = parser._subparsers._group_actions[0].choices["references"]._subparsers._group_actions[0].choices["build"]
    text = build.format_help()
    assert "--output DIR" in text and "--out " not in text


def test_version_is_the_manifest_s_and_pyproject_s(capsys):
    with pytest.raises(SystemExit) as stop:
        build_parser().parse_args(["--version"])
    assert stop.value.code == 0 and capsys.readouterr().out.strip() == f"ellimann {VERSION}"
    assert VERSION == tomllib.loads((ROOT / "blender_manifest.toml").read_text())["version"]
    assert VERSION == tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]


def test_measure_s_table_lines_up_and_a_skinned_json_gives_its_pieces_and_its_skin(tmp_path, capsys):
    plain, skinned = tmp_path / "m.json", tmp_path / "s.json"
    assert run(["synth", *REQUEST, "-o", str(plain)], capsys)[0] == 0
    code, stdout, err = run(["synth", *REQUEST, "--skin", "--skin-level", "preview", "-o", str(skinned)], capsys)
    assert code == 0, err
    said_skin = dict(re.findall(r"(He|Sh|Br|Wa|Hi) ([\d.]+)", stdout.split("skin ", 2)[2].split(";")[0]))
    said_pieces = dict(re.findall(r"(He|Sh|Br|Wa|Hi) ([\d.]+)", stdout.split("pieces' m_T")[1]))
    code, stdout, err = run(["measure", str(plain)], capsys)
    rows = stdout.splitlines()[1:]
    assert code == 0 and len(rows) == 11
    assert len({row.index(" cm") for row in rows}) == 1  # the values' column lines up
    assert len({len(row.split("  ", 2)[1].split(" ")[0]) for row in rows}) > 1  # whatever the keys' lengths
    code, stdout, err = run(["measure", str(skinned)], capsys)
    assert code == 0, err
    pieces, skin = stdout.split("\n", 1)[1].split("its skin (10 mm, made again")
    assert "its pieces (m_T and more)" in stdout.splitlines()[0]
    for key in FIVE:
        assert re.search(rf"^  {key} .* {said_pieces[key]} cm$", pieces, re.M), key
        assert re.search(rf"^  {key} .* {said_skin[key]} cm$", skin, re.M), key
    code, stdout, _ = run(["measure", str(skinned), "--json"], capsys)
    printed = json.loads(stdout)
    assert printed["skin"]["voxel_mm"] == 10.0 and list(printed)[:5] == list(FIVE)
    assert {k: round(printed["skin"][k], 2) for k in FIVE} == {k: float(v) for k, v in said_skin.items()}
    assert set(EXTRA_MEASUREMENTS) <= set(printed)


def glb(path, extras, nodes=()):
    """A minimal binary glTF: a JSON chunk holding ``extras`` as scene 0's ElliMann extras, and a binary chunk."""
    doc = {"asset": {"version": "2.0"}, "scenes": [{"extras": {EXTRAS_KEY: extras}}], "nodes": list(nodes)}
    chunk = json.dumps(doc).encode()
    chunk += b" " * (-len(chunk) % 4)
    binary = b"\0" * 8
    total = 12 + 8 + len(chunk) + 8 + len(binary)
    path.write_bytes(
        struct.pack("<4sII", b"glTF", 2, total)
        + struct.pack("<I4s", len(chunk), b"JSON")
        + chunk
        + struct.pack("<I4s", len(binary), b"BIN\0")
        + binary
    )
    return str(path)


def test_measure_reads_a_glb_s_extras_without_blender(tmp_path, capsys):
    extras = {"format": EXTRAS_FORMAT, "version": EXTRAS_VERSION, "name": "w", "measured_cm": FIVE}
    skin_node = {"name": "skin", "extras": {EXTRAS_KEY: {"kind": "SKIN", "skin": {"voxel_mm": 5.0, "blend": 0.6}}}}
    path = glb(tmp_path / "w.glb", extras, [skin_node])
    code, stdout, err = run(["measure", path], capsys)
    assert code == 0 and "w: m_T of its pieces as the file's extras record it" in stdout
    assert re.search(r"^  Br +Breast perimeter +101\.25 cm$", stdout, re.M)
    assert "also holds a skin (5 mm), whose measurements it does not record" in err
    code, stdout, _ = run(["measure", path, "--json"], capsys)
    assert code == 0 and json.loads(stdout) == FIVE
    other = glb(tmp_path / "o.glb", {"format": "someone.else", "version": 1})
    assert_one_line_error(*run(["measure", other], capsys)[::2], "o.glb", "'someone.else'")
    (tmp_path / "cut.glb").write_bytes((tmp_path / "w.glb").read_bytes()[:-4])
    assert_one_line_error(*run(["measure", str(tmp_path / "cut.glb")], capsys)[::2], "not a whole binary glTF")


def test_a_file_too_large_to_be_a_mannequin_is_refused_before_it_is_read(tmp_path, capsys):
    path = tmp_path / "huge.json"
    with open(path, "wb") as stream:  # a sparse file: its size without its bytes
        stream.truncate(3 * MAX_READ_BYTES)
    code, _, err = run(["measure", str(path)], capsys)
    assert_one_line_error(code, err, "huge.json is 300.0 MB", f"at most {MAX_READ_BYTES / 1e6:g} MB", "before reading")
    pose = tmp_path / "pose.json"
    os.link(path, pose)
    source = tmp_path / "in.csv"
    source.write_text("name,He,Sh,Br,Wa,Hi\nx,165,41.5,101.25,82.75,117.5\n", encoding="utf-8")
    code, _, err = run(["batch", str(source), "-o", str(tmp_path / "out"), "--pose", str(pose)], capsys)
    assert_one_line_error(code, err, "a pose file is at most")


def test_the_shipped_files_are_well_under_the_size_limit():
    largest = max(path.stat().st_size for path in REFERENCE_FOLDER.rglob("*.json"))
    assert largest < MAX_READ_BYTES / 100


def test_references_check_takes_a_shipped_set_s_name_and_never_prints_minus_zero(capsys):
    code, stdout, err = run(["references", "check", "female"], capsys)
    assert code == 0, err
    assert str(REFERENCE_FOLDER) in stdout.splitlines()[0]
    assert "worst m_T error" in stdout and "-0.0000%" not in stdout
    assert f"{-1e-9:+z.4%}" == "+0.0000%"  # what a rounding to zero prints


def test_measure_s_json_of_a_mannequin_stays_the_measurements_only(tmp_path, capsys):
    path = tmp_path / "m.json"
    Mannequin.load(REFERENCE_FOLDER / "average.json").save(path)
    code, stdout, _ = run(["measure", str(path), "--json"], capsys)
    assert code == 0 and list(json.loads(stdout)) == [*FIVE, *EXTRA_MEASUREMENTS]
