"""``ellimann sizes`` and ``synth`` with Blender: FBX avatars (the format table's fbx row: the skin on its bones, in
the T-pose with Mixamo's names here, decimated under the budget and measured again within 2 mm) and .glb files
beside the .json, the report giving what each FBX measures, and the run's line-up picture; an avatar without a skin
or in a pose that is no rest pose is refused in one line before any work."""

import csv
import pathlib
import re

import bpy
import numpy as np
import pytest

from devkit.cli_runs import assert_one_line_error, run
from ellimann_addon.core.files import incomplete
from ellimann_addon.core.formats.avatar import DECIMATED_TOLERANCE_CM, bone_names
from ellimann_addon.core.sizing.rows import UNITS

DATA = pathlib.Path(__file__).resolve().parents[2] / "data" / "sizing"
REQUEST = ["--he", "165", "--sh", "41.5", "--br", "101.25", "--wa", "82.75", "--hi", "117.5"]
BUDGET = 12_000  # under the body skin's 26,692 triangles: every avatar is decimated


@pytest.fixture(scope="module")
def chart_run(tmp_path_factory):
    from ellimann_addon import cli

    folder = tmp_path_factory.mktemp("sizes") / "out"
    argv = ["sizes", str(DATA / "brand_chart.csv"), "-o", str(folder), "--format", "fbx,glb,json", "-q"]
    argv += ["--pose", "t_pose", "--bones", "mixamo", "--max-triangles", str(BUDGET)]
    code = cli.main(argv)
    return code, folder


def test_a_chart_s_avatars_as_fbx_each_within_2_mm_with_a_line_up(chart_run):
    code, folder = chart_run
    assert code == 0
    names = sorted(p.name for p in folder.iterdir())
    assert names == sorted(
        [f"{size}.{kind}" for size in ("S", "M", "L") for kind in ("fbx", "glb", "json")]
        + ["lineup.png", "report.csv", "report.md"]
    )
    for path in folder.iterdir():
        assert incomplete(path) is None, path.name
    with open(folder / "report.csv", newline="", encoding="utf-8") as stream:
        rows = list(csv.DictReader(stream))
    assert {row["size"] for row in rows} == {"S", "M", "L"} and {row["status"] for row in rows} == {"ok"}
    for row in rows:  # what each FBX measures once decimated, in the chart's unit: within 2 mm of the row
        assert int(row["fbx_triangles"]) <= BUDGET
        off = abs(float(row["fbx_measured"]) - float(row["requested"])) * UNITS[row["unit"]]
        assert off <= DECIMATED_TOLERANCE_CM, row
    assert "![The run's skins in size order](lineup.png)" in (folder / "report.md").read_text()
    image = bpy.data.images.load(str(folder / "lineup.png"))
    width, height = image.size
    pixels = np.array(image.pixels[:]).reshape(height, width, 4)
    drawn = (pixels[..., :3].mean(axis=2) < 0.9).any(axis=0)  # the columns something is drawn in
    starts = np.flatnonzero(drawn[1:] & ~drawn[:-1])
    assert width > height and len(starts) + drawn[0] == 3  # three bodies side by side, apart


def test_the_fbx_stands_in_the_t_pose_with_mixamo_s_names(chart_run):
    _, folder = chart_run
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.import_scene.fbx(filepath=str(folder / "M.fbx"), automatic_bone_orientation=False)
    (rig,) = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    (skin,) = [o for o in bpy.data.objects if o.type == "MESH"]
    heads = {bone.name: np.array(rig.matrix_world @ bone.head_local) for bone in rig.data.bones}
    assert sorted(heads) == sorted(bone_names("mixamo"))
    for side in ("Left", "Right"):  # arms out level: the hand at the shoulder's height
        arm, hand = heads[f"mixamorig:{side}Arm"], heads[f"mixamorig:{side}Hand"]
        assert abs(hand[2] - arm[2]) < 0.01
    assert len(skin.data.polygons) <= BUDGET and [m.type for m in skin.modifiers] == ["ARMATURE"]


@pytest.mark.parametrize(
    "options, words",
    [
        ([], ["an FBX avatar is the mannequin's skin on its bones: ask for a skin (--skin)"]),
        (["--skin", "--pose", "sit"], ["an FBX avatar stands in its rest pose, a_pose or t_pose, not 'sit'"]),
        (["--skin", "--max-triangles", "100"], ["--max-triangles must be at least 5,000"]),
    ],
)
def test_synth_refuses_an_avatar_it_cannot_write_before_any_work(tmp_path, capsys, options, words):
    code, stdout, stderr = run(["synth", *REQUEST, "-o", str(tmp_path / "x.fbx"), *options], capsys)
    assert_one_line_error(code, stderr, *words)
    assert stdout == "" and list(tmp_path.iterdir()) == []


def test_synth_writes_an_avatar_with_its_proxy(tmp_path, capsys):
    path = tmp_path / "a.fbx"
    code, stdout, stderr = run(["synth", *REQUEST, "--skin", "-o", str(path), "--proxy"], capsys)
    assert code == 0, stderr
    assert stdout.startswith(f"wrote {path}:") and incomplete(path) is None
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.import_scene.fbx(filepath=str(path))
    meshes = sorted(o.name for o in bpy.data.objects if o.type == "MESH")
    assert meshes == ["ElliMann Avatar", "ElliMann Collision Proxy"]


def test_pose_and_batch_write_avatars_in_the_pose_asked(tmp_path, capsys):
    """``pose IN.json --pose t_pose --skin -o x.fbx`` stands the avatar in the T-pose; a ``batch --skin`` row writes
    one too (every job's avatar options reach the writer)."""
    source = tmp_path / "m.json"
    assert run(["synth", *REQUEST, "--skin", "-o", str(source)], capsys)[0] == 0
    code, _, stderr = run(["pose", str(source), "--pose", "t_pose", "--skin", "-o", str(tmp_path / "t.fbx")], capsys)
    assert code == 0, stderr
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.import_scene.fbx(filepath=str(tmp_path / "t.fbx"), automatic_bone_orientation=False)
    (rig,) = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    shoulder, wrist = (rig.matrix_world @ rig.data.bones[name].head_local for name in ("L_Shoulder", "L_Wrist"))
    assert abs(wrist.z - shoulder.z) < 0.01  # the T-pose
    table = tmp_path / "rows.csv"
    table.write_text("name,He,Sh,Br,Wa,Hi\nana,165,41.5,101.25,82.75,117.5\n")
    code, _, stderr = run(["batch", str(table), "-o", str(tmp_path / "b"), "--format", "fbx", "--skin", "-q"], capsys)
    assert code == 0, stderr
    assert incomplete(tmp_path / "b" / "ana.fbx") is None


def test_a_size_whose_avatar_cannot_be_decimated_within_2_mm_fails_and_leaves_nothing(tmp_path, capsys):
    folder = tmp_path / "out"
    # Size XL (50) decimated to 5,000 triangles reads its waist 2.7 mm off (docs/formats/fbx_avatar.md)
    argv = ["sizes", str(DATA / "women_run.vst"), "-o", str(folder), "--sizes", "50", "--format", "json,fbx"]
    code, stdout, stderr = run([*argv, "--max-triangles", "5000", "--no-picture", "-q"], capsys)
    assert code == 1 and "0 of 1 avatars written" in stdout
    (failed,) = [line for line in stderr.splitlines() if "failed:" in line]
    assert re.search(r"size 'XL': fbx: the avatar \([\d,]+ triangles\) misses the request by [+-]0\.\d\d cm", failed)
    assert failed.endswith("raise the triangle budget (--max-triangles)")
    assert sorted(p.name for p in folder.iterdir()) == ["report.csv", "report.md"]  # its .json removed too
