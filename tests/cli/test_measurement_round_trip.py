"""The round trip: ``measure FILE --write-measurements OUT`` writes what it measures as a Seamly2D .vit, a FreeSewing
set (.json) or a size chart's row (.csv), the format by OUT's extension; read back by ``core.sizing.readers`` (as
``sizes`` reads them) every value returns as measured, in the unit asked; a mannequin with a skin writes its skin's;
a bad OUT is refused in one line before anything is measured."""

import contextlib
import io
import json

import pytest

from devkit.cli_runs import assert_one_line_error
from ellimann_addon.cli import main
from ellimann_addon.core.measurements import ALL_MEASUREMENTS
from ellimann_addon.core.sizing.readers import read_measurement_file

REQUEST = ["--he", "165", "--sh", "41.5", "--br", "101.25", "--wa", "82.75", "--hi", "117.5", "--neck", "34"]


def cli(*args):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(arg) for arg in args])
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def skinned(tmp_path_factory):
    """A body-skinned mannequin (.json) and its skin alone (.obj), and what measure --json says of each."""
    folder = tmp_path_factory.mktemp("round")
    for kind in ("json", "obj"):
        code, _, err = cli("synth", *REQUEST, "--skin", "-o", folder / f"m.{kind}")
        assert code == 0, err
    code, out, err = cli("measure", folder / "m.json", "--json")
    assert code == 0, err
    skin = {key: value for key, value in json.loads(out)["skin"].items() if key in ALL_MEASUREMENTS}
    code, out, err = cli("measure", folder / "m.obj", "--json")
    assert code == 0, err
    return folder, skin, json.loads(out)


@pytest.mark.parametrize(
    "name, unit, within_cm",  # measure --json's own rounding (5e-5 cm) and the unit's last digit
    [("m.vit", "cm", 1e-4), ("m-mm.vit", "mm", 1e-4), ("m.json", None, 1e-4), ("m.csv", "inch", 2.54e-4)],
)
def test_what_measure_shows_of_a_skinned_mannequin_returns_as_written(tmp_path, skinned, name, unit, within_cm):
    folder, skin, _ = skinned
    out = tmp_path / name.replace("-mm", "")
    options = ["--write-unit", unit] if unit else []
    code, stdout, stderr = cli("measure", folder / "m.json", "--json", "--write-measurements", out, *options)
    assert code == 0, stderr
    shown = json.loads(stdout)["skin"]
    assert {key: shown[key] for key in skin} == skin  # what it prints is what it prints without writing
    (said,) = stderr.strip().splitlines()
    assert said.startswith(f"ellimann measure: wrote {out}: {len(skin)} measurements as ")
    read = read_measurement_file(out)
    (row,) = read.rows
    assert row.ok and not row.predicted and not row.unknown, row.error
    assert read.unit == (unit or "mm")
    for key, value in skin.items():  # the skin's, not the pieces'
        assert row.values[key] == pytest.approx(value, abs=within_cm), key


def test_a_body_mesh_s_measurements_written_as_a_chart_row(tmp_path, skinned):
    folder, _, mesh = skinned
    out = tmp_path / "row.csv"
    code, _, stderr = cli("measure", folder / "m.obj", "--write-measurements", out)
    assert code == 0, stderr
    lines = out.read_text().splitlines()
    assert lines[0].split(",")[0] == "size" and lines[1].startswith("unit,cm") and lines[2].startswith("m,")
    (row,) = read_measurement_file(out).rows
    assert row.values == pytest.approx({key: mesh[key] for key in row.values}, abs=1e-4)
    assert set(row.values) == set(mesh)  # what could be measured, nothing more


@pytest.mark.parametrize(
    "out, options, words",
    [
        ("m.txt", [], ["--write-measurements", "m.txt: must end in .vit, .json, .csv"]),
        ("m.json", ["--write-unit", "inch"], ["--write-unit inch: a FreeSewing set is in mm by its definition"]),
    ],
)
def test_a_bad_output_is_refused_before_anything_is_measured(tmp_path, skinned, out, options, words):
    folder, _, _ = skinned
    code, stdout, stderr = cli("measure", folder / "m.json", "--write-measurements", tmp_path / out, *options)
    assert_one_line_error(code, stderr, *words)
    assert stdout == "" and not (tmp_path / out).exists()
    code, _, stderr = cli("measure", folder / "m.json", "--write-measurements", folder / "m.json")
    assert_one_line_error(code, stderr, "is the file measured; write to another")
