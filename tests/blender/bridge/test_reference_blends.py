"""The .blend twins in reference_blends/ (the female set), reference_blends/male/ and the fine sets' folders hold the
same mannequins as the JSON files, measured at the same section heights."""

import pathlib

import bpy
import numpy as np
import pytest

from ellimann_addon.blender.bridge import convert
from ellimann_addon.core.mannequin.model import Mannequin

FOLDER = pathlib.Path(__file__).resolve().parents[3] / "reference_blends"
STEMS = ("base_mannequin", "small_slim", "tall_slim", "small_chubby", "tall_chubby", "average")


@pytest.mark.parametrize(
    "folder",
    [FOLDER, FOLDER / "male", FOLDER / "female-fine", FOLDER / "male-fine"],
    ids=["female", "male", "female-fine", "male-fine"],
)
@pytest.mark.parametrize("stem", STEMS)
def test_blend_and_json_agree(stem, folder):
    json_twin = Mannequin.load(folder / f"{stem}.json")
    bpy.ops.wm.open_mainfile(filepath=str(folder / f"{stem}.blend"))
    collections = convert.mannequin_collections()
    assert [c.name for c in collections] == [json_twin.name]
    blend = convert.collection_to_mannequin(collections[0]).reordered(json_twin.topology)
    assert blend.role == json_twin.role
    assert (blend.reference_set, blend.section_fractions) == (json_twin.reference_set, json_twin.section_fractions)
    assert blend.measurements == (None if json_twin.measurements is None else pytest.approx(json_twin.measurements))
    # Blender keeps matrix_world in single precision
    assert np.allclose(blend.center, json_twin.center, atol=1e-6)
    assert np.allclose(blend.rotation, json_twin.rotation, atol=1e-5)
    assert np.allclose(blend.semi_axes, json_twin.semi_axes, rtol=1e-5)
    assert blend.measure() == pytest.approx(json_twin.measure(), rel=1e-4)
