"""A male mannequin end to end: the panel's Male choice synthesizes from the shipped male set, with cushions;
Measure cuts it at the male heights; it exports, drapes' garments fit its sections, and the command line
chooses the set by name, per row in a batch."""

import csv
import json

import bpy
import numpy as np
import pytest

from devkit.blender_scene import state
from devkit.cli_runs import assert_one_line_error, run
from ellimann_addon.blender.bridge import convert
from ellimann_addon.core.constants import SECTION_FRACTIONS
from ellimann_addon.core.drape.garments import make_garment
from ellimann_addon.core.formats.glb import EXTRAS_KEY, read_glb_json
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.reference_set import load_reference_set
from ellimann_addon.core.synthesis.shipped import SHIPPED_SETS

REQUEST = dict(He=180.0, Sh=52.0, Br=108.0, Wa=96.0, Hi=104.0)  # inside the male ranges L


@pytest.fixture(scope="module")
def male():
    return load_reference_set(SHIPPED_SETS["male"])


def test_the_panel_synthesizes_a_male_mannequin_with_cushions_that_measures_and_exports(male, tmp_path):
    props = bpy.context.scene.ellimann_synthesis
    props.reference_set, props.output, props.mode = "MALE", "CUSHIONS", "EXACT"
    for key, value in REQUEST.items():
        setattr(props, key.lower(), value)
    assert bpy.ops.ellimann.synthesize_mannequin() == {"FINISHED"}
    collection = props.target
    assert collection.ellimann.reference_set == "male"
    assert [o for o in bpy.data.objects if o.ellimann.kind == "CUSHION"]
    mannequin = convert.collection_to_mannequin(collection)
    assert mannequin.section_fractions == male.section_fractions != SECTION_FRACTIONS
    bpy.context.view_layer.objects.active = next(o for o in collection.objects if o.ellimann.kind == "ELLIPSOID")
    assert bpy.ops.ellimann.measure_mannequin(source="ELLIPSOIDS") == {"FINISHED"}
    assert tuple(collection.ellimann.measured) == pytest.approx(tuple(REQUEST.values()), rel=1e-4)
    path = tmp_path / "male.glb"
    assert bpy.ops.ellimann.export_mannequin(filepath=str(path)) == {"FINISHED"}
    assert read_glb_json(path)["scenes"][0]["extras"][EXTRAS_KEY]["name"] == collection.name


def test_garments_put_their_girth_lines_at_the_male_sections(male):
    """The T-shirt's body tube has a ring exactly on each girth line: the male set's, not the female's."""
    mannequin = male.mannequins[male.names.index("average")]
    z = make_garment(mannequin, "t_shirt").vertices[:, 2]
    height = mannequin.measure()["He"] / 100.0  # registered: the feet on z = 0
    for key in ("Wa", "Hi"):
        assert np.abs(z - male.section_fractions[key] * height).min() < 1e-9, key
        assert np.abs(z - SECTION_FRACTIONS[key] * height).min() > 1e-6, key


def test_the_command_line_chooses_the_set_by_name_and_per_batch_row(tmp_path, capsys):
    out = tmp_path / "m.json"
    args = [f"--{k.lower()}={v:g}" for k, v in REQUEST.items()]
    code, stdout, err = run(["synth", *args, "-o", str(out), "--references", "male"], capsys)
    assert code == 0 and not err, err
    assert Mannequin.load(out).reference_set == "male"
    code, _, err = run(["synth", *args, "-o", str(out), "--references", "mael"], capsys)
    assert_one_line_error(code, err, "references", "neither a shipped set")
    table = tmp_path / "rows.csv"
    table.write_text(
        "name,He,Sh,Br,Wa,Hi,references\nhim,180,52,108,96,104,male\nher,159,43,117,104,117,\n"
        "typo,159,43,117,104,117,mael\n",
        encoding="utf-8",
    )
    code, _, err = run(["batch", str(table), "-o", str(tmp_path / "out")], capsys)
    assert code == 1 and "line 4" in err and "references" in err
    with open(tmp_path / "out" / "report.csv", encoding="utf-8") as stream:
        rows = {row["name"]: row for row in csv.DictReader(stream)}
    assert (rows["him"]["references"], rows["her"]["references"]) == ("male", "female")
    assert rows["typo"]["status"] == "error"
    for name, chosen in (("him", "male"), ("her", "female")):
        saved = Mannequin.load(tmp_path / "out" / f"{name}.json")
        assert saved.reference_set == chosen
        assert max(abs(float(rows[name][f"{k}_error_pct"])) for k in MEASUREMENTS) < 1e-3
    code, stdout, _ = run(["measure", str(tmp_path / "out" / "him.json"), "--json"], capsys)
    printed = json.loads(stdout)  # the five, then the extra measurements
    assert {key: printed[key] for key in MEASUREMENTS} == pytest.approx(
        dict(zip(MEASUREMENTS, (180, 52, 108, 96, 104))), rel=1e-5
    )
    code, stdout, _ = run(["measure", str(tmp_path / "out" / "him.json"), "--json", "--references", "female"], capsys)
    assert json.loads(stdout)["Hi"] != pytest.approx(104.0, rel=1e-3)  # cut at the female hip height


def test_folder_without_a_folder_is_refused_and_changes_nothing():
    props = bpy.context.scene.ellimann_synthesis
    props.reference_set, props.references = "FOLDER", ""
    before = state()
    with pytest.raises(RuntimeError, match="References is empty"):
        bpy.ops.ellimann.synthesize_mannequin()
    assert state() == before
