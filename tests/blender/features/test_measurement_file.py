"""Open Measurement File (the Synthesize panel): a .vit, a FreeSewing set or a chart's size fills the five and the
extra measurements' fields as a preset does, the status line saying which values were used, predicted and not used;
a man's file chooses the male set; a size outside the set's range is made as a field out of it would be (a
warning); a bad file or size changes nothing and says why in one line; one undo step, and
with Live on one live update."""

import pathlib

import bpy
import pytest

from devkit.blender_scene import state
from ellimann_addon.blender import ids
from ellimann_addon.blender.features.synthesize import live, panel
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ellimann_addon.core.sizing.readers import read_measurement_file
from ellimann_addon.core.sizing.writers import write_vit

DATA = pathlib.Path(__file__).resolve().parents[2] / "data" / "sizing"
START = dict(zip(MEASUREMENTS, (159.0, 43.0, 117.0, 104.0, 117.0)))


@pytest.fixture
def props():
    props = bpy.context.scene.ellimann_synthesis
    props.reference_set = "FEMALE"
    for key, value in START.items():
        setattr(props, key.lower(), value)
    props.use_calf, props.calf = True, 41.0  # ticked before: a file that gives no calf unticks it
    return props


def fields(props):
    five = {key: round(getattr(props, key.lower()), 4) for key in MEASUREMENTS}
    extra = {key: round(getattr(props, key), 4) for key in EXTRA_MEASUREMENTS if getattr(props, f"use_{key}")}
    return five, extra, props.reference_set


def open_file(path, size="", capfd=None):
    result = bpy.ops.ellimann.open_measurement_file("EXEC_DEFAULT", True, filepath=str(path), size=size)
    return result, (capfd.readouterr().out if capfd is not None else "")


def test_a_vit_fills_the_five_and_its_extra_measurements_and_says_what_it_used(props, capfd):
    row = read_measurement_file(DATA / "jane.vit").rows[0]
    result, out = open_file(DATA / "jane.vit", capfd=capfd)
    assert result == {"FINISHED"}
    five, extra, reference_set = fields(props)
    assert five == pytest.approx(row.request(), abs=1e-4)  # Sh predicted, the others as written
    assert extra == pytest.approx({"neck": 32.4, "thigh": 56.0, "calf": 35.5, "crotch_height": 75.9}, abs=1e-4)
    assert reference_set == "FEMALE"
    status = "Jane Doe (jane.vit): used He, Br, Wa, Hi, neck, thigh, calf, crotch_height; predicted Sh 43.34 cm"
    assert f"Info: {status} (± 1.13); not used: shoulder_length, arm_upper_circ, " in out


def test_a_chart_s_size_by_its_label_and_a_man_s_file_chooses_the_male_set(props, tmp_path, capfd):
    chart = read_measurement_file(DATA / "brand_chart.csv")
    result, _ = open_file(DATA / "brand_chart.csv", "l")  # any case
    assert result == {"FINISHED"}
    assert fields(props)[0] == pytest.approx(chart.rows[2].request(), abs=1e-4)
    assert fields(props)[1] == pytest.approx({"thigh": 58.0, "calf": 37.0}, abs=1e-4)
    result, out = open_file(DATA / "misses_chart.csv", capfd=capfd)  # its first size: outside, by 0.18 cm
    assert result == {"FINISHED"} and fields(props)[0]["Br"] == pytest.approx(33 * 2.54)
    assert "Warning: Br 83.82 cm is outside every reference set's range" in out
    man = tmp_path / "john.vit"
    write_vit(man, {"He": 178.0, "Sh": 50.0, "Br": 100.0, "Wa": 88.0, "Hi": 100.0}, name="John Doe", sex="male")
    props.reference_set = "FEMALE_FINE"
    assert open_file(man)[0] == {"FINISHED"}
    assert fields(props) == ({"He": 178.0, "Sh": 50.0, "Br": 100.0, "Wa": 88.0, "Hi": 100.0}, {}, "MALE_FINE")


@pytest.mark.parametrize(
    "make_file, size, words",
    [
        (lambda d: d / "gone.vit", "", "cannot be read"),
        (lambda d: DATA / "brand_chart.csv", "XXL", "brand_chart.csv: no size 'XXL'; it has S, M, L"),
        (
            lambda d: (
                (d / "inch.vit").write_text((DATA / "jane.vit").read_text().replace(">cm<", ">inch<"))
                and d / "inch.vit"
            ),
            "",
            "height = 165 inch is 419.1 cm, not an adult's He (120-230 cm); as cm it would be 165 cm",
        ),
        (
            lambda d: (d / "bad.csv").write_text("size,bustt\nunit,cm\nS,84\n") and d / "bad.csv",
            "",
            "column 'bustt' is not a measurement ElliMann knows (did you mean 'bust'?)",
        ),
    ],
)
def test_a_bad_file_or_size_changes_nothing_and_says_why(props, tmp_path, make_file, size, words):
    before, scene = fields(props), state()
    with pytest.raises(RuntimeError) as refused:
        open_file(make_file(tmp_path), size)
    assert words in str(refused.value) and str(refused.value).count("\n") <= 1
    assert fields(props) == before and state() == scene


def test_one_undo_step_and_one_live_update(props, monkeypatch):
    bpy.ops.ellimann.synthesize_mannequin()
    props.live = True
    calls = []
    monkeypatch.setattr(live, "live_update", lambda scene: calls.append(scene) or 0.0)
    bpy.ops.ed.undo_push(message="Before")
    before = fields(props)
    assert open_file(DATA / "jane.vit")[0] == {"FINISHED"}
    assert len(calls) == 1  # the five and four extra fields set: one live update
    after = fields(props)
    assert after != before
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert fields(bpy.context.scene.ellimann_synthesis) == before
    assert bpy.ops.ed.redo() == {"FINISHED"}
    assert fields(bpy.context.scene.ellimann_synthesis) == after


def test_the_panel_offers_it():
    from devkit.ui_recorder import draw_panel

    assert ids.OPEN_MEASUREMENT_FILE in draw_panel(panel.ELLIMANN_PT_synthesize).operators()
