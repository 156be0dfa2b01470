"""Every row of a size run read from a file is met by exact mode: the five within its tolerance (the predicted
ones too), every extra measurement the file gives within 1 mm (what the lead's `sizes` command builds on)."""

import pathlib

import pytest

from ellimann_addon.core.sizing.readers import read_measurement_file
from ellimann_addon.core.synthesis.shipped import named_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize_extra

DATA = pathlib.Path(__file__).resolve().parents[2] / "data" / "sizing"


@pytest.mark.parametrize("name", ["women_run.vst", "jane.vit"])
def test_every_row_is_met(name):
    reference = named_reference_set("female")
    read = read_measurement_file(DATA / name)
    assert read.rows and not read.failed
    for row in read.rows:
        made = synthesize_extra(reference, row.request(), row.extra())
        assert made.missed == () or not made.missed, (row.label, made.missed)
        for key, value in row.request().items():
            assert made.measured[key] == pytest.approx(value, rel=1e-4), (row.label, key)
        for key, value in row.extra().items():
            assert abs(made.measured[key] - value) < 0.1, (row.label, key, made.measured[key], value)
