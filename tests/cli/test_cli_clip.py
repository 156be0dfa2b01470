"""``--pose clip.bvh`` on synth, pose and batch: the clip's frames in .json and MJCF keyframes, what its bones
became and what was clamped said on the command line (and in batch's report), --fps resampling, --rig forcing a
map, --keep-on-floor; an animation refused for .obj."""

import csv
import json

import numpy as np
import pytest

from devkit import bvh, clips
from devkit.cli_runs import assert_one_line_error, run
from ellimann_addon.core.formats.posed_files import read_pose
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.pose.clip import lowest_foot
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

REQUEST = ["--he", "165", "--sh", "41.5", "--br", "101.25", "--wa", "82.75", "--hi", "117.5"]


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    joints = Mannequin.load(REFERENCE_FOLDER / "average.json").joints
    return bvh.write_bvh(tmp_path_factory.mktemp("clip") / "walk.bvh", clips.convention_clip("cmu", joints, frames=20))


def test_synth_writes_the_clip_as_frames_and_says_what_became_of_it(tmp_path, clip, capsys):
    out = tmp_path / "woman.json"
    code, stdout, stderr = run(["synth", *REQUEST, "--pose", str(clip), "-o", str(out)], capsys)
    assert code == 0 and f"in pose {clip}" in stdout
    lines = stderr.splitlines()
    assert lines[0].startswith("ellimann synth: walk.bvh: 20 frames at 30 fps, 29 bones, units: CMU units")
    assert lines[1] == "ellimann synth: 24 of 24 joints placed from 29 bones by CMU names"
    assert lines[2] == "ellimann synth: bones not placed (5): LHipJoint, RHipJoint, Neck1, LThumb, RThumb"
    assert any(
        line.startswith("ellimann synth: warning: clamped to the limits: L_Knee about its x axis") for line in lines
    )
    assert lines[-1].startswith("ellimann synth: feet: ") and "--keep-on-floor" in lines[-1]
    section = json.loads(out.read_text())["pose"]
    assert section["name"] == "walk.bvh" and section["fps"] == pytest.approx(30.0, rel=1e-4)
    assert len(section["frames"]) == 20 and section["frames"][0]["name"] == "walk.bvh 1"


def test_pose_resamples_holds_the_feet_and_writes_keyframes(tmp_path, clip, capsys):
    rest = tmp_path / "rest.json"
    Mannequin.load(REFERENCE_FOLDER / "average.json").save(rest)
    out, held = tmp_path / "walk.xml", tmp_path / "held.json"
    code, stdout, _ = run(["pose", str(rest), "--pose", str(clip), "--fps", "60", "-o", str(out)], capsys)
    assert code == 0 and "(39 frames)" in stdout
    assert out.read_text().count("<key name=") == 39
    code, _, stderr = run(["pose", str(rest), "--pose", str(clip), "--keep-on-floor", "-o", str(held)], capsys)
    assert code == 0 and "feet: held on the floor in every frame" in stderr
    mannequin, frames = Mannequin.load(held), read_pose(held)
    rotations = np.stack([f.rotations for f in frames])
    lowest = lowest_foot(mannequin, mannequin.joints, rotations, np.stack([f.translation for f in frames]))
    assert np.abs(lowest).max() < 1e-6


def test_batch_writes_every_row_and_reports_each_rows_clamps(tmp_path, clip, capsys):
    source = tmp_path / "in.csv"
    source.write_text("He,Sh,Br,Wa,Hi,name\n160,40,95,80,105,a\n170,42,100,85,110,b\n", encoding="utf-8")
    out = tmp_path / "out"
    code, _, stderr = run(["batch", str(source), "-o", str(out), "--format", "json,mjcf", "--pose", str(clip)], capsys)
    assert code == 0 and stderr.count("joints placed from 29 bones") == 1
    for name in "ab":
        assert len(read_pose(out / f"{name}.json")) == 20
        assert (out / f"{name}.xml").read_text().count("<key name=") == 20
    with open(out / "report.csv", encoding="utf-8") as stream:
        messages = [row["message"] for row in csv.DictReader(stream)]
    assert all("clamped to the limits: L_Knee about its x axis" in m and "feet: " in m for m in messages)


def test_a_forced_rig_places_only_its_names(tmp_path, clip, capsys):
    code, _, stderr = run(
        ["synth", *REQUEST, "--pose", str(clip), "--rig", "mixamo", "-o", str(tmp_path / "x.json")], capsys
    )
    assert code == 0 and "by Mixamo names" in stderr and "LowerBack" in stderr  # not a Mixamo name: not placed


def test_a_limb_without_its_knee_is_written_with_a_warning(tmp_path, capsys):
    names = ["Hips", "LeftUpLeg", "LeftFoot", "RightUpLeg", "RightLeg", "RightFoot", "Spine", "Head"]
    parents = [-1, 0, 1, 0, 3, 4, 0, 6]
    heads = np.array([[0, 0, 0.9], [0.1, 0, 0.85], [0.1, 0, 0.08], [-0.1, 0, 0.85], [-0.1, 0, 0.47], [-0.1, 0, 0.08]])
    heads = np.vstack([heads, [[0, 0, 1.2], [0, 0, 1.5]]])
    path = bvh.write_bvh(
        tmp_path / "stiff.bvh",
        bvh.Clip(names, parents, heads, np.broadcast_to(np.eye(3), (2, 8, 3, 3)), {0: np.repeat(heads[:1], 2, 0)}),
    )
    code, _, stderr = run(["synth", *REQUEST, "--pose", str(path), "-o", str(tmp_path / "x.json")], capsys)
    assert code == 0
    assert (
        "ellimann synth: warning: will not bend, the clip has no bone for them: L_Knee (between L_Hip and L_Ankle)"
        in stderr
    )


def test_a_clip_is_an_animation_obj_cannot_hold(tmp_path, clip, capsys):
    code, _, err = run(["synth", *REQUEST, "--pose", str(clip), "-o", str(tmp_path / "x.obj")], capsys)
    assert_one_line_error(code, err, "is an animation and a .obj file holds none")
    assert not (tmp_path / "x.obj").exists()


def test_a_clip_that_does_not_exist_is_refused_in_one_line(tmp_path, capsys):
    code, _, err = run(
        ["synth", *REQUEST, "--pose", str(tmp_path / "none.bvh"), "-o", str(tmp_path / "x.json")], capsys
    )
    assert_one_line_error(code, err, "cannot read", "none.bvh")
    assert not list(tmp_path.iterdir())
