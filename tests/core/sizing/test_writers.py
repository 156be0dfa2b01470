"""A body's measurements written as a .vit, a FreeSewing set and a chart row, read back by the readers: each
value returns as written, under the format's own name where it has the same measurement."""

import json
import xml.etree.ElementTree as ElementTree

import pytest

from ellimann_addon.core.constants import REFERENCE_MEASUREMENTS
from ellimann_addon.core.measurements import EXTRA_DEFAULTS
from ellimann_addon.core.sizing.readers import read_measurement_file
from ellimann_addon.core.sizing.rows import UNITS, SizingError
from ellimann_addon.core.sizing.writers import write_chart_row, write_freesewing, write_vit

BODY = {**REFERENCE_MEASUREMENTS["average"], **EXTRA_DEFAULTS, "neck": 33.37, "thigh": 61.25}


@pytest.mark.parametrize("unit", ["cm", "mm", "inch"])
def test_vit_round_trip(tmp_path, unit):
    path = tmp_path / "body.vit"
    write_vit(path, BODY, name="Ava Average", sex="female", unit=unit)
    read = read_measurement_file(path)
    (row,) = read.rows
    assert row.ok, row.error
    assert read.unit == unit and read.sex == "female" and row.label == "Ava Average"
    assert row.predicted == {} and row.unused == {} and row.unknown == ()
    for key, value in BODY.items():
        assert row.values[key] == pytest.approx(value, abs=0.6e-4 * UNITS[unit]), key
    names = {m.get("name") for m in ElementTree.parse(path).getroot().iter("m")}
    assert {"height", "bust_circ", "waist_circ", "hip_circ", "neck_mid_circ", "leg_crotch_to_floor"} <= names
    assert {"@ellimann_Sh", "@ellimann_upper_arm", "@ellimann_arm_length"} <= names  # no known name is the same


def test_freesewing_round_trip(tmp_path):
    path = tmp_path / "body.json"
    write_freesewing(path, BODY, name="Ava")
    data = json.loads(path.read_text())
    assert data["measurements"]["chest"] == pytest.approx(BODY["Br"] * 10) and "seat" in data["measurements"]
    assert set(data["ellimann"]) == {"units", "He", "Sh", "calf", "arm_length"}
    row = read_measurement_file(path, sex="female").rows[0]
    assert row.ok and row.predicted == {} and row.unknown == ()
    for key, value in BODY.items():
        assert row.values[key] == pytest.approx(value, abs=1e-9), key


@pytest.mark.parametrize("unit", ["cm", "inch"])
def test_chart_row_round_trip(tmp_path, unit):
    path = tmp_path / "row.csv"
    write_chart_row(path, "avg", BODY, unit=unit)
    row = read_measurement_file(path).rows[0]
    assert row.ok and row.label == "avg" and row.predicted == {}
    for key, value in BODY.items():
        assert row.values[key] == pytest.approx(value, abs=0.6e-4 * UNITS[unit]), key


def test_bad_values_are_refused_and_nothing_is_written(tmp_path):
    for bad in ({"He": -1.0}, {"Xx": 3.0}, {"He": float("nan")}, {}):
        with pytest.raises(SizingError):
            write_vit(tmp_path / "x.vit", bad)
    assert list(tmp_path.iterdir()) == []
