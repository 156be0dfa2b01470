"""``ellimann sizes``: a measurement file (tests/data/sizing: a multisize .vst, a .vit, a FreeSewing set, size charts
in cm and in inches) made into one avatar per size. Every avatar's skin as written (the .obj, Y up) meets its row
within the skin's tolerance, measured here by the body-mesh measurer from the file alone; the report gives the
file's values in the file's own unit and which were predicted; a row that fails is reported and the rest go on
(exit 1); a whole file that cannot be read, or a command line that cannot be run, is refused in one line with
nothing written; numpy alone writes .json and .obj (the line-up picture skipped and said), and .fbx is refused
without Blender. The picture and .fbx/.glb with Blender: tests/blender/cli/test_cli_sizes_blender.py."""

import contextlib
import csv
import io
import json
import pathlib

import numpy as np
import pytest

from devkit.cli_runs import assert_one_line_error, without_blender
from ellimann_addon.cli import main
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.measure.body import measure_body_mesh
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ellimann_addon.core.sizing.readers import read_measurement_file
from ellimann_addon.core.sizing.rows import UNITS
from ellimann_addon.core.sizing.writers import write_vit
from ellimann_addon.core.synthesis.bodies import load_set_bodies
from ellimann_addon.core.synthesis.misses import SKIN_MISS_CM
from ellimann_addon.core.synthesis.shipped import named_reference_set, reference_folder

DATA = pathlib.Path(__file__).resolve().parents[1] / "data" / "sizing"
QUIET = ["--no-picture", "-q"]


def sizes(*args):
    """cli.main(["sizes", *args]) in this process: (code, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["sizes", *map(str, args)])
    return code, out.getvalue(), err.getvalue()


def report_rows(folder):
    with open(folder / "report.csv", newline="", encoding="utf-8") as stream:
        return list(csv.DictReader(stream))


def skin_from_obj(path):
    """(vertices in ElliMann's axes (Z up), faces) of a skin's .obj (Y up: a scene point (x, y, z) is (x, z, -y))."""
    lines = path.read_text().splitlines()
    written = np.array([line.split()[1:] for line in lines if line.startswith("v ")], dtype=float)
    faces = np.array([line.split()[1:] for line in lines if line.startswith("f ")], dtype=np.int64) - 1
    return np.stack([written[:, 0], -written[:, 2], written[:, 1]], axis=1), faces


@pytest.fixture(scope="module")
def female_bodies():
    return load_set_bodies(reference_folder("female"))


def measured_as_written(folder, name, bodies):
    """{key: cm} of a size's skin as its .obj holds it: measured as ``ellimann measure`` reads any body mesh (the
    set's section heights, its arms from the set's labels, the neck where a tape drawn tight settles)."""
    vertices, faces = skin_from_obj(folder / f"{name}.obj")
    return measure_body_mesh(vertices, faces, bodies.fractions, None, bodies.arms).values


def check_every_avatar_meets_its_row(folder, path, bodies, **reading):
    read = read_measurement_file(path, **reading)
    made = {row["size"]: row for row in report_rows(folder)}
    for row in read.rows:
        assert made[row.label]["status"] == "ok", made[row.label]
        name = made[row.label]["file"]
        found = measured_as_written(folder, name, bodies)
        for key, wanted in {**row.request(), **row.extra()}.items():
            assert abs(found[key] - wanted) <= SKIN_MISS_CM, (row.label, key, found[key], wanted)
        recorded = Mannequin.load(folder / f"{name}.json")
        assert recorded.skin["kind"] == "body" and recorded.skin["request"] == pytest.approx(
            {**row.request(), **row.extra()}
        )


def test_a_multisize_run_gives_an_avatar_per_size_each_meeting_its_row(tmp_path, female_bodies):
    folder = tmp_path / "run"
    code, stdout, stderr = sizes(DATA / "women_run.vst", "-o", folder, "--sizes", "42,52", *QUIET)
    assert code == 0, stderr
    assert stdout.startswith(f"ellimann sizes: 2 of 2 avatars written to {folder} (female set, body skin)")
    assert sorted(p.name for p in folder.iterdir()) == [
        "XS.json",
        "XS.obj",
        "XXL.json",
        "XXL.obj",
        "report.csv",
        "report.md",
    ]
    check_every_avatar_meets_its_row(folder, DATA / "women_run.vst", female_bodies, sizes=[42, 52])
    assert "the file does not say the person's sex" in stderr  # said once, not per size
    text = (folder / "report.md").read_text()
    assert "| XS | Sh | predicted (± 1.13) | cm | 40.88 |" in text and "No line-up picture" in text


@pytest.mark.slow
def test_every_size_of_the_run_meets_its_row(tmp_path, female_bodies):
    folder = tmp_path / "run"
    code, _, stderr = sizes(DATA / "women_run.vst", "-o", folder, "--format", "obj,json", *QUIET)
    assert code == 0, stderr
    check_every_avatar_meets_its_row(folder, DATA / "women_run.vst", female_bodies)
    assert [row["size"] for row in report_rows(folder)][::8] == ["XS", "S", "M", "L", "XL", "XXL"]  # size order


@pytest.mark.parametrize("name", ["jane.vit", "freesewing_set.json", "brand_chart.csv"])
def test_a_person_or_a_chart_in_its_own_unit(tmp_path, name, female_bodies):
    folder = tmp_path / "out"
    code, _, stderr = sizes(DATA / name, "-o", folder, *QUIET)
    assert code == 0, stderr
    check_every_avatar_meets_its_row(folder, DATA / name, female_bodies)
    read = read_measurement_file(DATA / name)
    for line in report_rows(folder):  # the file's values, in its unit, as the file gives them
        row = next(row for row in read.rows if row.label == line["size"])
        key = line["measurement"]
        assert line["unit"] == read.unit_of(key)
        if line["source"] == "given":
            given_name, given, unit = row.given[key]
            assert line["name_in_file"] == given_name and unit == line["unit"]
            assert float(line["requested"]) == pytest.approx(given, abs=1e-4)
        else:
            assert key in row.predicted and float(line["predicted_sd"]) > 0
        difference = float(line["measured"]) - float(line["requested"])
        assert float(line["difference"]) == pytest.approx(difference, abs=2e-4)
        assert abs(difference) * UNITS[line["unit"]] <= SKIN_MISS_CM


def test_a_chart_in_inches_reports_in_inches_and_a_failing_row_lets_the_rest_go_on(tmp_path):
    chart = tmp_path / "misses.csv"
    chart.write_text(
        "Size,Height (in),Bust (in),Waist (in),Hip (in),Neck (in)\n2,65,33,25.5,35.5,12.75\n8,65,36,28.5,38.5,13.5\n"
    )
    folder = tmp_path / "out"
    code, stdout, stderr = sizes(chart, "-o", folder, *QUIET)
    assert code == 1
    lines = stderr.strip().splitlines()
    assert lines[-2].startswith(f"ellimann sizes: failed: {chart} row '2': Br 83.82 cm is outside every reference")
    assert "(0.18 cm away)" in lines[-2] and "--extrapolate" in lines[-2]
    assert lines[-1] == f"ellimann sizes: error: 1 row(s) failed; see {folder / 'report.md'}"
    assert "1 of 2 avatars written" in stdout
    assert sorted(p.name for p in folder.iterdir()) == ["8.json", "8.obj", "report.csv", "report.md"]
    rows = report_rows(folder)
    assert rows[0]["size"] == "2" and rows[0]["status"] == "error" and "row '2'" in rows[0]["message"]
    made = {row["measurement"]: row for row in rows[1:]}
    assert {row["unit"] for row in made.values()} == {"inch"}
    assert [float(made[key]["requested"]) for key in ("He", "Br", "Wa", "Hi", "neck")] == [65, 36, 28.5, 38.5, 13.5]
    assert made["Sh"]["source"] == "predicted"
    for row in made.values():  # the skin in inches: within 1 mm
        assert abs(float(row["measured"]) - float(row["requested"])) <= SKIN_MISS_CM / 2.54
    text = (folder / "report.md").read_text()
    assert "## Failed rows" in text and "- 2: " in text and "values in inch" in text
    # --extrapolate: the row is made, with the distance as a warning
    code, _, stderr = sizes(chart, "-o", tmp_path / "again", "--extrapolate", *QUIET)
    assert code == 0, stderr
    assert "size 2: warning: Br 83.82 cm is outside every reference set's range" in stderr


def test_a_size_whose_increments_make_a_girth_negative_fails_and_the_others_are_made(tmp_path):
    table = tmp_path / "steep.vst"
    text = (DATA / "women_run.vst").read_text()
    table.write_text(
        text.replace('"waist_circ" base="74" size_increase="4"', '"waist_circ" base="74" size_increase="40"')
    )
    code, _, stderr = sizes(table, "-o", tmp_path / "out", "--sizes", "42,46", *QUIET)
    assert code == 1
    failed = [line for line in stderr.splitlines() if "failed:" in line]
    assert len(failed) == 1 and f"{table} size XS: waist_circ is -6 cm" in failed[0]
    assert "the increments make it negative at this size" in failed[0]
    assert (tmp_path / "out" / "M.obj").is_file() and not (tmp_path / "out" / "XS.obj").exists()


def test_a_value_that_only_makes_sense_in_cm_in_a_file_in_inches_says_so(tmp_path):
    person = tmp_path / "inch.vit"
    person.write_text((DATA / "jane.vit").read_text().replace("<unit>cm</unit>", "<unit>inch</unit>"))
    code, _, stderr = sizes(person, "-o", tmp_path / "out", *QUIET)
    assert code == 1
    (failed,) = [line for line in stderr.splitlines() if "failed:" in line]
    assert "height = 165 inch is 419.1 cm, not an adult's He" in failed and "is the file's unit cm, not inch?" in failed
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["report.csv", "report.md"]


def _edited(tmp_path, name, old, new):
    path = tmp_path / name
    path.write_text((DATA / name).read_text().replace(old, new))
    return path


@pytest.mark.parametrize(
    "make_file, options, words",
    [
        (
            lambda d: _edited(d, "jane.vit", "waist_circ + 24", "waistt_circ + 24"),
            [],
            ["hip_circ: the formula 'waistt_circ + 24' refers to 'waistt_circ', which the file does not hold"],
        ),
        (
            lambda d: _edited(d, "jane.vit", 'value="165"', 'value="leg_crotch_to_floor * 2"'),
            [],
            ["is circular (height -> leg_crotch_to_floor -> height)"],
        ),
        (
            lambda d: _edited(d, "brand_chart.csv", "size,height,bust", "size,height,bustt"),
            [],
            ["column 'bustt' is not a measurement ElliMann knows (did you mean 'bust'?)"],
        ),
        (lambda d: DATA / "jane.vit", ["--sex", "male"], ["the file says female, but male was asked"]),
        (lambda d: DATA / "jane.vit", ["--sizes", "42"], ["--sizes chooses the run of a multisize table (.vst)"]),
        (lambda d: DATA / "women_run.vst", ["--sizes", "big"], ["--sizes takes comma-separated numbers"]),
        (lambda d: DATA / "jane.vit", ["--format", "json,stl"], ["--format takes a comma-separated list of blend"]),
        (lambda d: DATA / "jane.vit", ["--bones", "mixamo"], ["--bones is an option of an FBX avatar: write a .fbx"]),
        (lambda d: DATA / "jane.vit", ["--skin-kind", "body", "--skin-level", "preview"], ["--skin-level is a"]),
        (lambda d: d / "missing.vit", [], ["missing.vit: no such file"]),
    ],
)
def test_bad_input_is_one_line_and_nothing_is_written(tmp_path, make_file, options, words):
    path = make_file(tmp_path)
    code, stdout, stderr = sizes(path, "-o", tmp_path / "out", *options, *QUIET)
    assert_one_line_error(code, stderr, *words)
    assert stdout == "" and not (tmp_path / "out").exists()


def test_a_man_s_file_is_made_on_the_male_set(tmp_path):
    male = named_reference_set("male")
    targets = dict(zip(MEASUREMENTS, male.measurements[2]))
    person = tmp_path / "john.vit"
    write_vit(person, targets, name="John Doe", sex="male")
    code, stdout, stderr = sizes(person, "-o", tmp_path / "out", *QUIET)
    assert code == 0, stderr
    assert (
        "(male set, body skin)" in stdout
        and "made on the `male` reference set" in (tmp_path / "out" / "report.md").read_text()
    )
    assert Mannequin.load(tmp_path / "out" / "John_Doe.json").reference_set == "male"
    # Without Sh (no survey of men is shipped to predict it): the row fails, saying so; with --stats it would not
    without = {key: value for key, value in targets.items() if key != "Sh"}
    write_vit(person, without, name="John Doe", sex="male")
    code, _, stderr = sizes(person, "-o", tmp_path / "out2", *QUIET)
    assert code == 1 and "Sh missing and not predicted: no male survey statistics are shipped" in stderr


def test_numpy_alone_writes_json_and_obj_and_says_the_picture_is_skipped(tmp_path):
    folder = tmp_path / "out"
    code, stdout, stderr = without_blender("sizes", str(DATA / "jane.vit"), "-o", str(folder), "-q")
    assert code == 0, stderr
    assert "ellimann sizes: no line-up picture: it needs Blender (the bpy module)" in stderr
    assert sorted(p.name for p in folder.iterdir()) == ["Jane_Doe.json", "Jane_Doe.obj", "report.csv", "report.md"]
    assert json.loads((folder / "Jane_Doe.json").read_text())["skin"]["kind"] == "body"
    for kind in ("fbx", "glb"):
        code, stdout, stderr = without_blender(
            "sizes", str(DATA / "jane.vit"), "-o", str(tmp_path / kind), "--format", kind
        )
        assert_one_line_error(code, stderr, f"--format {kind} needs Blender: the bpy module is not installed")
        assert not (tmp_path / kind).exists()


def test_extra_measurements_given_are_met_and_predicted_ones_are_not_asked(tmp_path):
    """A row asks for the extra measurements its file gives (exact mode meets them) and the five, a predicted one
    among them; the report has a line for each, nothing for what the file does not give."""
    code, _, stderr = sizes(DATA / "jane.vit", "-o", tmp_path, *QUIET)
    assert code == 0, stderr
    keys = [row["measurement"] for row in report_rows(tmp_path)]
    assert keys == [
        *MEASUREMENTS,
        *(key for key in EXTRA_MEASUREMENTS if key in ("neck", "thigh", "calf", "crotch_height")),
    ]


def test_ctrl_c_keeps_the_sizes_made_reports_them_and_leaves_nothing_of_the_one_being_made(tmp_path, monkeypatch):
    from ellimann_addon.cli import sizes as sizes_command

    made = sizes_command.make_row

    def interrupted_on_the_second(request, *args):
        if "S" in request.options.name.split()[-1:]:
            with open(request.outputs[0], "w") as half:  # a file of the size being made, already written
                half.write("{")
            raise KeyboardInterrupt
        return made(request, *args)

    monkeypatch.setattr(sizes_command, "make_row", interrupted_on_the_second)
    folder = tmp_path / "run"
    code, _, stderr = sizes(DATA / "women_run.vst", "-o", folder, "--sizes", "42,44,46", *QUIET)
    assert code == 130
    assert "interrupted: 1 of 3 sizes done" in stderr
    assert sorted(p.name for p in folder.iterdir()) == ["XS.json", "XS.obj", "report.csv", "report.md"]
    assert [row["size"] for row in report_rows(folder)] == ["XS"] * 8
    assert "Interrupted (Ctrl-C) after 1 of 3 sizes" in (folder / "report.md").read_text()
