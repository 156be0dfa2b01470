"""Bad data files on the command line and in Blender: one error line naming the file or the field and the
accepted range or type, exit code 1, nothing written, never a traceback (issue 10)."""

import copy
import json
import re
import time

import bpy
import numpy as np
import pytest
from mathutils import Matrix

from devkit import synthetic
from devkit.blender_scene import parts
from devkit.cli_runs import assert_one_line_error, python_m, run
from ellimann_addon.blender.bridge.convert import collection_to_mannequin
from ellimann_addon.blender.services import drape as drape_module
from ellimann_addon.blender.services.drape import MAX_CLOTH_VERTICES, DrapeSettings, check_cloth_size, drape
from ellimann_addon.core.drape import garments
from ellimann_addon.core.errors import ElliMannError, MannequinError
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.synthesis.synthesize import REFERENCE_FOLDER

AVERAGE = REFERENCE_FOLDER / "average.json"
REQUEST = ["--he", "165", "--sh", "41.5", "--br", "101.25", "--wa", "82.75", "--hi", "117.5"]


@pytest.fixture(scope="module")
def references(tmp_path_factory):
    return str(synthetic.write_reference_folder(tmp_path_factory.mktemp("rm")))


def _edited(change):
    data = json.loads(AVERAGE.read_text())
    change(data)
    return json.dumps(data, ensure_ascii=False)


BAD_FILES = {
    "measurements list": (_edited(lambda d: d.update(measurements_cm=[159, 43])), ["measurements_cm", "a list"]),
    "measurements string": (_edited(lambda d: d.update(measurements_cm="average")), ["measurements_cm", "a string"]),
    "utf-16": (AVERAGE.read_text().encode("utf-16"), ["UTF-16", "UTF-8"]),
    "latin-1": (_edited(lambda d: d.update(name="Zoë")).encode("latin-1"), ["not UTF-8"]),
    "nested": ("[" * 100_000 + "]" * 100_000, ["nested too deeply"]),
    "top level list": ("[]", ["holds a list"]),
    "semi-axes 1e300": (
        _edited(lambda d: d["ellipsoids"][0]["semi_axes"].__setitem__(0, 1e300)),
        ["semi_axes", "1e+300 m", "accepted range 1e-05 to 3 m"],
    ),
    "semi-axes 1e-300": (
        _edited(lambda d: d["ellipsoids"][0]["semi_axes"].__setitem__(0, 1e-300)),
        ["semi_axes", "1e-300 m", "accepted range 1e-05 to 3 m"],
    ),
    "centre 1e308": (
        _edited(lambda d: d["ellipsoids"][0]["center"].__setitem__(0, 1e308)),
        ["center", "x = 1e+308 m", "accepted range -100 to 100 m"],
    ),
    "duplicate names": (
        _edited(lambda d: d["ellipsoids"].append(copy.deepcopy(d["ellipsoids"][0]))),
        ["name: is used twice"],
    ),
}


def write_bad(tmp_path, case):
    content, words = BAD_FILES[case]
    path = tmp_path / "bad.json"
    path.write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
    return path, words


@pytest.mark.parametrize("case", list(BAD_FILES))
def test_measure_refuses_a_bad_file_in_one_line_naming_it(tmp_path, capsys, case):
    path, words = write_bad(tmp_path, case)
    for extra in ([], ["--json"]):
        code, out, err = run(["measure", str(path), *extra], capsys)
        assert_one_line_error(code, err, str(path), *words)
        assert out == ""


@pytest.mark.parametrize("case", ["measurements list", "utf-16", "nested", "semi-axes 1e300", "centre 1e308"])
def test_drape_refuses_a_bad_file_in_one_line_and_writes_nothing(tmp_path, capsys, case):
    path, words = write_bad(tmp_path, case)
    out = tmp_path / "x.blend"
    code, stdout, err = run(["drape", str(path), "-o", str(out)], capsys)
    assert_one_line_error(code, err, str(path), *words)
    assert stdout == "" and not out.exists()


def test_python_m_reports_a_list_of_measurements_without_a_traceback(tmp_path):
    path, _ = write_bad(tmp_path, "measurements list")
    done = python_m("measure", str(path), "--json")
    assert done.returncode == 1 and done.stdout == "" and "Traceback" not in done.stderr
    assert done.stderr.strip().splitlines() == [
        f"ellimann measure: error: {path}: measurements_cm: must be an object of He, Sh, Br, Wa, Hi in cm (or null), "
        "got a list"
    ]


@pytest.mark.parametrize("case", ["measurements list", "utf-16"])
def test_references_with_a_bad_file_are_one_line(tmp_path, capsys, references, case):
    import shutil

    folder = tmp_path / "rm"
    shutil.copytree(references, folder)
    content, words = BAD_FILES[case]
    (folder / "average.json").write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
    out = tmp_path / "x.json"
    code, _, err = run(["synth", *REQUEST, "-o", str(out), "--references", str(folder)], capsys)
    assert_one_line_error(code, err, "average.json", *words)
    assert not out.exists()


def test_references_naming_a_file_say_it_is_a_file(tmp_path, capsys, references):
    out = tmp_path / "x.json"
    code, _, err = run(["synth", *REQUEST, "-o", str(out), "--references", f"{references}/average.json"], capsys)
    assert_one_line_error(code, err, "average.json", "is a file, not a folder")
    assert "does not exist" not in err and not out.exists()


def test_measure_json_never_prints_a_non_finite_number(tmp_path, capsys, monkeypatch):
    path = tmp_path / "m.json"
    Mannequin.load(AVERAGE).save(path)
    measured = Mannequin.measure
    monkeypatch.setattr(Mannequin, "measure", lambda self: dict(measured(self), Sh=float("inf")))
    code, out, err = run(["measure", str(path), "--json"], capsys)
    assert_one_line_error(code, err, str(path), "m_T is not finite", "Sh inf")
    assert out == ""


# ------------------------------------------------------------------------------------------------ drape size


def test_drape_refuses_a_cloth_too_fine_at_once_with_the_figures(tmp_path, capsys):
    out = tmp_path / "x.blend"
    start = time.perf_counter()
    code, stdout, err = run(["drape", str(AVERAGE), "--edge", "0.2", "-o", str(out)], capsys)
    assert time.perf_counter() - start < 20  # it used to run out of memory building the garment
    assert_one_line_error(
        code, err, "tube_dress", "0.2 cm edges", "vertices", "GB", f"limit {MAX_CLOTH_VERTICES:,} vertices"
    )
    assert stdout == "" and not out.exists()
    vertices = int(re.search(r"about ([\d,]+) vertices", err).group(1).replace(",", ""))
    assert vertices > 3 * MAX_CLOTH_VERTICES
    fits = float(re.search(r"an edge of ([\d.]+) cm or more fits", err).group(1))
    mannequin = Mannequin.load(AVERAGE)
    assert garments.estimate_vertices(mannequin, "tube_dress", fits / 100) <= MAX_CLOTH_VERTICES
    assert garments.estimate_vertices(mannequin, "tube_dress", (fits - 0.01) / 100) > MAX_CLOTH_VERTICES


@pytest.mark.parametrize("edge", ["0.1", "25", "nan"])
def test_edge_errors_quote_the_flag_in_cm(tmp_path, capsys, edge):
    code, _, err = run(["drape", str(AVERAGE), "--edge", edge, "-o", str(tmp_path / "x.blend")], capsys)
    assert_one_line_error(code, err, "--edge", "from 0.2 to 20 cm", f"got {float(edge):g} cm")
    assert " m," not in err and "0.002" not in err


def test_drape_warns_about_a_large_cloth(tmp_path, capsys, toy, monkeypatch):
    monkeypatch.setattr(drape_module, "WARN_CLOTH_VERTICES", 10)
    toy.save(tmp_path / "toy.json")
    code, _, err = run(
        [
            "drape",
            str(tmp_path / "toy.json"),
            "--frames",
            "2",
            "--edge",
            "6",
            "--no-cushions",
            "-o",
            str(tmp_path / "x.blend"),
        ],
        capsys,
    )
    assert code == 0, err
    warning = [line for line in err.splitlines() if "warning" in line]
    assert len(warning) == 1 and re.search(r"about [\d,]+ vertices and need about [\d.]+ GB", warning[0])


def test_drape_refuses_before_building_anything(toy):
    before = {kind: len(getattr(bpy.data, kind)) for kind in ("objects", "meshes", "collections")}
    settings = DrapeSettings(edge=0.02, max_vertices=500)
    with pytest.raises(ElliMannError, match=r"cloth: a t_shirt with 2 cm edges .* \(limit 500 vertices.*or more fits"):
        drape(toy, "t_shirt", settings)
    assert {kind: len(getattr(bpy.data, kind)) for kind in before} == before
    garment = garments.tube_dress(toy, edge=0.05)
    with pytest.raises(ElliMannError, match=rf"about {len(garment.vertices)} vertices"):
        check_cloth_size(toy, garment, DrapeSettings(max_vertices=100))
    with pytest.raises(ElliMannError, match="max_vertices"):
        DrapeSettings(max_vertices=0).checked()


# ------------------------------------------------------------------------------------------------ collections


@pytest.mark.parametrize(
    "scale, words",
    [
        (1e-6, ["semi_axes: 1e-06 m is not a plausible semi-axis", "accepted range 1e-05 to 3 m"]),
        (50.0, ["semi_axes: 50 m", "accepted range 1e-05 to 3 m"]),
    ],
)
def test_a_collection_with_an_implausible_scale_is_refused_like_a_file(toy_collection, scale, words):
    obj = parts(toy_collection)["3.a Pelvis"]
    obj.scale = (scale, 0.1, 0.1)
    bpy.context.view_layer.update()
    with pytest.raises(MannequinError) as info:
        collection_to_mannequin(toy_collection)
    for word in ["'3.a Pelvis'", *words]:
        assert word in str(info.value)


def test_a_collection_far_from_the_origin_is_refused(toy_collection):
    obj = parts(toy_collection)["1.a Head"]
    obj.matrix_world = Matrix.Translation((0.0, 500.0, 1.6)) @ Matrix.Diagonal((0.1, 0.1, 0.12, 1.0))
    bpy.context.view_layer.update()
    with pytest.raises(
        MannequinError,
        match=r"'1.a Head' center: y = 500 m is too far from the origin "
        r"\(accepted range -100 to 100 m\)",
    ):
        collection_to_mannequin(toy_collection)
    obj.matrix_world = Matrix.Translation((0.0, 99.0, 1.6)) @ Matrix.Diagonal((0.1, 0.1, 0.12, 1.0))
    bpy.context.view_layer.update()
    assert np.isclose(collection_to_mannequin(toy_collection).center[0, 1], 99.0)


def test_a_partial_target_is_not_kept_by_a_collection(toy):
    from ellimann_addon.blender.bridge.convert import mannequin_to_collection

    # Before: KeyError in write_collection_props (drape of a JSON whose measurements_cm lacks a key).
    collection = mannequin_to_collection(toy.copy(measurements={"He": 160.0}))
    assert not collection.ellimann.has_target
    assert collection_to_mannequin(collection).measurements is None
    full = {"He": 160.0, "Sh": 40.0, "Br": 90.0, "Wa": 70.0, "Hi": 95.0}
    assert collection_to_mannequin(mannequin_to_collection(toy.copy(measurements=full))).measurements == full
