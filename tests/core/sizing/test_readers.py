"""Reading measurement files: Seamly2D / Valentina .vit and .vst, FreeSewing sets, CSV size charts (real-shaped
files written from the formats' specifications, tests/data/sizing/): the values used, recognised but not used,
not recognised and predicted, each checked against the file read independently here."""

import json
import math
import pathlib
import xml.etree.ElementTree as ElementTree

import numpy as np
import pytest

from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.sizing.readers import read_measurement_file
from ellimann_addon.core.sizing.rows import SizingError
from ellimann_addon.core.synthesis.population import load_population

DATA = pathlib.Path(__file__).resolve().parents[2] / "data" / "sizing"


def test_vit_values_used_unused_and_predicted():
    read = read_measurement_file(DATA / "jane.vit")
    assert (read.format, read.unit, read.sex) == ("vit", "cm", "female")
    (row,) = read.rows
    assert row.ok and row.label == "Jane Doe"
    root = ElementTree.parse(DATA / "jane.vit").getroot()
    raw = {m.get("name"): m.get("value") for m in root.iter("m")}
    assert row.values["He"] == float(raw["height"])
    assert row.values["Hi"] == float(raw["waist_circ"]) + 24.0  # a formula of another measurement
    assert row.values["crotch_height"] == pytest.approx(float(raw["height"]) * 0.46, rel=1e-15)
    assert row.predictors == {
        "neck_base": float(raw["neck_mid_circ"]) + 3.6,
        "biacromial": float(raw["width_shoulder"]),
    }
    assert set(row.predicted) == {"Sh"}
    assert {"shoulder_length", "arm_upper_circ", "arm_shoulder_tip_to_wrist", "head_circ", "@sleeve_ease"} == set(
        row.unused
    )
    assert row.unknown == ()
    used = {name for name, _, _ in row.given.values()} | {"neck_circ", "width_shoulder"}
    assert used | set(row.unused) == set(raw)  # every name of the file is accounted for, once


def test_a_vit_in_mm_or_inches_reads_the_same_body(tmp_path):
    text = (DATA / "jane.vit").read_text()
    cm = read_measurement_file(DATA / "jane.vit").rows[0]
    for unit, scale in (("mm", 10.0), ("inch", 1 / 2.54)):
        root = ElementTree.fromstring(text)
        root.find("unit").text = unit
        for m in root.iter("m"):
            value = m.get("value")
            if all(c in "0123456789." for c in value):
                m.set("value", repr(float(value) * scale))
            elif "+" in value:  # waist_circ + 24, neck_mid_circ + 3.6: the constant is in the file's unit too
                name, _, constant = value.partition("+")
                m.set("value", f"{name.strip()} + {float(constant) * scale!r}")
        path = tmp_path / f"jane_{unit}.vit"
        path.write_text(ElementTree.tostring(root, encoding="unicode"))
        row = read_measurement_file(path).rows[0]
        assert row.ok, row.error
        for key, value in cm.values.items():
            assert row.values[key] == pytest.approx(value, rel=1e-12), (unit, key)


def test_prediction_is_the_surveys_conditional_mean():
    row = read_measurement_file(DATA / "jane.vit").rows[0]
    population = load_population("ansur2_female")
    keys = list(population.keys)
    given = {**{k: v for k, v in row.values.items() if k != "Sh"}, **row.predictors}
    g = [keys.index(k) for k in keys if k in given]
    s = keys.index("Sh")
    cov, mean = population.covariance, population.mean
    x = np.array([given[keys[i]] for i in g]) - mean[g]
    expected = mean[s] + cov[s, g] @ np.linalg.solve(cov[np.ix_(g, g)], x)
    spread = math.sqrt(cov[s, s] - cov[s, g] @ np.linalg.solve(cov[np.ix_(g, g)], cov[g, s]))
    assert row.predicted["Sh"][0] == pytest.approx(expected, rel=1e-12)
    assert row.predicted["Sh"][1] == pytest.approx(spread, rel=1e-9)
    assert row.values["Sh"] == row.predicted["Sh"][0]
    assert 0 < spread < math.sqrt(cov[s, s])  # the others tell something about Sh


def test_a_body_at_the_survey_mean_predicts_the_mean(tmp_path):
    population = load_population("ansur2_female")
    mean = dict(zip(population.keys, population.mean))
    values = ",".join(repr(float(mean[k])) for k in ("He", "Br", "Wa", "Hi"))  # numpy 2's repr says np.float64
    (tmp_path / "mean.csv").write_text("size,He,Br,Wa,Hi\nunit,cm,cm,cm,cm\nM," + values + "\n")
    row = read_measurement_file(tmp_path / "mean.csv", extrapolate=True).rows[0]
    assert row.values["Sh"] == pytest.approx(mean["Sh"], rel=1e-12)


def test_a_male_file_missing_one_of_the_five_is_refused_naming_it(tmp_path):
    text = (DATA / "jane.vit").read_text().replace("<gender>female</gender>", "<gender>male</gender>")
    text = text.replace('value="92.5"', 'value="100"').replace('"76"', '"88"')
    (tmp_path / "john.vit").write_text(text)
    row = read_measurement_file(tmp_path / "john.vit").rows[0]
    assert not row.ok and "\n" not in row.error
    assert "john.vit" in row.error and "Sh missing" in row.error and "no male survey statistics" in row.error
    with pytest.raises(SizingError, match="the file says male, but female was asked"):
        read_measurement_file(tmp_path / "john.vit", sex="female")


def _vst_expected(path):
    """The run's rows as the grading formula gives them, read here with ElementTree alone."""
    root = ElementTree.parse(path).getroot()
    size, height = root.find("size"), root.find("height")
    base_size, base_height = float(size.get("base")), float(height.get("base"))
    sizes = np.arange(float(size.get("min")), float(size.get("max")) + 1e-9, float(size.get("step")))
    table = {
        m.get("name"): [float(m.get(k)) for k in ("base", "size_increase", "height_increase")] for m in root.iter("m")
    }
    return sizes, {
        s: {n: b + (s - base_size) / 2 * ks + (base_height - base_height) / 6 * kh for n, (b, ks, kh) in table.items()}
        for s in sizes
    }


def test_vst_gives_one_row_per_size_graded_by_the_tools_formula():
    read = read_measurement_file(DATA / "women_run.vst")
    sizes, expected = _vst_expected(DATA / "women_run.vst")
    assert [row.label for row in read.rows] == ["XS", "S", "M", "L", "XL", "XXL"]
    for row, size in zip(read.rows, sizes):
        assert row.ok, row.error
        for key, (name, value, unit) in row.given.items():
            assert unit == "cm" and value == pytest.approx(expected[size][name], abs=1e-12)
            assert row.values[key] == pytest.approx(expected[size][name], abs=1e-12)
        assert set(row.predicted) == {"Sh"}
    sh = [row.values["Sh"] for row in read.rows]
    assert all(b > a for a, b in zip(sh, sh[1:]))  # a larger size predicts broader shoulders


def test_vst_heights_and_grade_breaks(tmp_path):
    text = (DATA / "women_run.vst").read_text()
    read = read_measurement_file(DATA / "women_run.vst", heights=[158, 170], sizes=[44, 48])
    assert [row.label for row in read.rows] == ["S/158", "L/158", "S/170", "L/170"]
    for row in read.rows:
        size = {"S": 44, "L": 48}[row.label[0]]
        height = float(row.label[2:])
        assert row.values["He"] == pytest.approx(164 + (height - 164) / 6 * 6)
        assert row.values["crotch_height"] == pytest.approx(76 + (height - 164) / 6 * 2.8)
        assert row.values["Br"] == pytest.approx(92 + (size - 46) / 2 * 4)
    broken = text.replace(
        '<m name="bust_circ" base="92" size_increase="4" height_increase="0"/>',
        '<m name="bust_circ" base="92" size_increase="4" height_increase="0"><sizeRules>'
        '<break threshold="48" increment="5"/></sizeRules></m>',
    )
    (tmp_path / "breaks.vst").write_text(broken)
    rows = {row.label: row for row in read_measurement_file(tmp_path / "breaks.vst").rows}
    # up from 46: the step 46->48 starts below the break (4), 48->50 and 50->52 at or above it (5)
    assert rows["XXL"].values["Br"] == pytest.approx(92 + 4 + 5 + 5)
    assert rows["XS"].values["Br"] == pytest.approx(92 - 4 - 4)  # down: steps starting at 46 and 44, below it


def test_vst_negative_girth_fails_that_size_only(tmp_path):
    text = (DATA / "women_run.vst").read_text().replace('<m name="leg_calf_circ"', '<m name="x"')
    text = text.replace('min="42" max="52"', 'min="22" max="52"').replace(
        '<m name="leg_thigh_upper_circ" base="57" size_increase="2.2"',
        '<m name="leg_thigh_upper_circ" base="57" size_increase="4.8"',
    )
    (tmp_path / "negative.vst").write_text(text)
    rows = read_measurement_file(tmp_path / "negative.vst").rows
    failed = [row for row in rows if not row.ok]
    # thigh = 57 + (s - 46) / 2 * 4.8 <= 0 for s <= 22.25: size 22 alone
    bad = next(row for row in failed if row.label == "22")
    assert "leg_thigh_upper_circ" in bad.error and "negative" in bad.error and "negative.vst" in bad.error
    assert all(row.ok or row.error for row in rows)
    assert any(row.ok for row in rows)


def test_freesewing_set_in_mm():
    read = read_measurement_file(DATA / "freesewing_set.json")
    assert (read.format, read.unit) == ("freesewing", "mm")
    (row,) = read.rows
    assert row.ok, row.error
    data = json.loads((DATA / "freesewing_set.json").read_text())["measurements"]
    for key, name in (("Br", "chest"), ("Wa", "waist"), ("Hi", "seat"), ("neck", "neck"), ("crotch_height", "inseam")):
        assert row.values[key] == pytest.approx(data[name] / 10.0, rel=1e-15)
    assert set(row.predicted) == {"He", "Sh"}  # FreeSewing has no stature and no width across the deltoids
    assert "hips" in row.unused and "shoulderToShoulder" in row.unused
    assert row.unknown == ("myOwnMeasurement",)


def test_chart_in_inches_the_row_outside_every_set_fails_with_how_far():
    read = read_measurement_file(DATA / "misses_chart.csv")
    assert read.unit == "inch" and read.units["Br"] == "inch"
    rows = {row.label: row for row in read.rows}
    bad = rows["2"]
    assert not bad.ok and "outside every reference set's range" in bad.error
    assert f"{84 - 33 * 2.54:.2f} cm away" in bad.error
    for label, row in rows.items():
        if label != "2":
            assert row.ok, row.error
            assert set(row.predicted) == {"Sh"}
    assert rows["10"].values["Br"] == pytest.approx(37 * 2.54)
    again = read_measurement_file(DATA / "misses_chart.csv", extrapolate=True)
    assert all(row.ok for row in again.rows)
    assert any("outside every reference set's range" in w for w in again.rows[0].warnings)


def test_chart_with_a_unit_row_and_a_column_not_used():
    read = read_measurement_file(DATA / "brand_chart.csv")
    assert [row.label for row in read.rows] == ["S", "M", "L"] and all(row.ok for row in read.rows)
    assert read.rows[1].request()["He"] == 164.0 and read.rows[1].extra() == {"thigh": 55.0, "calf": 35.5}


@pytest.mark.parametrize(
    "name, text, words",
    [
        ("nounit.vit", lambda t: t.replace("<unit>cm</unit>", ""), ["<unit> is missing", "never guesses"]),
        ("badunit.vit", lambda t: t.replace("<unit>cm</unit>", "<unit>ft</unit>"), ["<unit> is 'ft'"]),
        ("ref.vit", lambda t: t.replace("waist_circ + 24", "waist + 24"), ["hip_circ", "'waist'", "does not hold"]),
        (
            "loop.vit",
            lambda t: t.replace('value="76"', 'value="hip_circ - 24"'),
            ["circular", "hip_circ", "waist_circ"],
        ),
        ("doctype.vit", lambda t: t.replace("<smis>", '<!DOCTYPE smis [<!ENTITY x "y">]><smis>'), ["DOCTYPE"]),
        ("wrong.vit", lambda t: t.replace("smis>", "pattern>"), ["root element is <pattern>"]),
    ],
)
def test_bad_vit_files_are_refused_in_one_line(tmp_path, name, text, words):
    (tmp_path / name).write_text(text((DATA / "jane.vit").read_text()))
    with pytest.raises(SizingError) as caught:
        read_measurement_file(tmp_path / name)
    message = str(caught.value)
    assert "\n" not in message and name in message
    for word in words:
        assert word in message


def test_a_value_that_only_makes_sense_in_another_unit_says_which(tmp_path):
    (tmp_path / "inches.csv").write_text("size,height,bust,waist,hip\nunit,in,in,in,in\nM,65,92,74,100\n")
    row = read_measurement_file(tmp_path / "inches.csv").rows[0]
    assert not row.ok and "bust = 92 inch is 233.7 cm" in row.error and "as cm it would be 92 cm" in row.error


@pytest.mark.parametrize(
    "text, words",
    [
        ("size,height,bust,wasit,hip\nunit,cm,cm,cm,cm\nM,165,92,74,100\n", ["column 'wasit'", "did you mean 'waist'"]),
        ("size,height,bust,waist,hip\nM,165,92,74,100\n", ["column 'height' has no unit", "never guesses"]),
        ("size,height (ft),bust,waist,hip\nM,5.5,92,74,100\n", ["column 'height' has a unit ElliMann does not know"]),
        ("size\n", ["needs a header row and at least one size"]),
    ],
)
def test_bad_charts_are_refused_in_one_line(tmp_path, text, words):
    (tmp_path / "chart.csv").write_text(text)
    with pytest.raises(SizingError) as caught:
        read_measurement_file(tmp_path / "chart.csv")
    for word in words:
        assert word in str(caught.value)


def test_a_bad_cell_fails_its_row_and_the_run_goes_on(tmp_path):
    (tmp_path / "chart.csv").write_text(
        "size,height,bust,waist,hip,thigh\nunit,cm,cm,cm,cm,cm\nS,160,84,66,90,52\nM,164,9O,72,96,55\n"
        "L,168,96,78,102,110\n"
    )
    rows = read_measurement_file(tmp_path / "chart.csv").rows
    assert rows[0].ok
    assert not rows[1].ok and "row 'M'" in rows[1].error and "bust is '9O', not a number" in rows[1].error
    assert not rows[2].ok and "thigh 110 cm >= Hi 102 cm" in rows[2].error  # contradicts the hip
    assert rows[1].values == {} and rows[2].values == {}


def test_every_row_request_is_the_five():
    for row in read_measurement_file(DATA / "women_run.vst").rows:
        assert tuple(row.request()) == MEASUREMENTS
