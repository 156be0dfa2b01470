"""``--pose`` on the command line: synth, batch and pose write posed .json/.xml/.obj; unknown poses, joints
beyond their limits, mannequins without joints and animations for formats without one are refused in one line,
with nothing written."""

import json

import numpy as np
import pytest

from devkit.cli_runs import assert_one_line_error, run
from ellimann_addon.core.formats.posed_files import read_pose
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.skeleton import cross_joint_pairs
from ellimann_addon.core.pose.standard import standard_pose, walk
from ellimann_addon.core.synthesis.shipped import FEMALE_FINE_SET, FEMALE_SET

REQUEST = ["--he", "165", "--sh", "41.5", "--br", "101.25", "--wa", "82.75", "--hi", "117.5"]


@pytest.fixture(scope="module")
def rest(tmp_path_factory):
    from ellimann_addon import cli

    path = tmp_path_factory.mktemp("rest") / "rest.json"
    assert cli.main(["synth", *REQUEST, "-o", str(path)]) == 0
    return path


def test_pose_json_is_the_rest_mannequin_with_its_joints_and_the_frames(tmp_path, rest, capsys):
    out = tmp_path / "walk.json"
    code, stdout, _ = run(["pose", str(rest), "--pose", "walk", "-o", str(out)], capsys)
    assert code == 0 and "(24 frames)" in stdout
    mannequin, original = Mannequin.load(out), Mannequin.load(rest)
    assert np.array_equal(mannequin.center, original.center) and np.array_equal(mannequin.joints, original.joints)
    section = json.loads(out.read_text())["pose"]
    assert section["version"] == 1 and section["fps"] == 24 and len(section["frames"]) == 24
    frames, expected = read_pose(out), walk(original.joints)
    assert all(np.allclose(a.rotations, b.rotations, atol=1e-12) for a, b in zip(frames, expected))


def test_synth_with_a_pose_writes_the_pose_of_the_synthesized_mannequin(tmp_path, rest, capsys):
    out = tmp_path / "sit.json"
    code, stdout, _ = run(["synth", *REQUEST, "--pose", "sit", "-o", str(out)], capsys)
    assert code == 0 and "in pose sit" in stdout
    (frame,) = read_pose(out)
    assert np.allclose(frame.rotations, standard_pose("sit", Mannequin.load(rest).joints).rotations, atol=1e-12)


def test_batch_with_a_pose_writes_each_row_posed(tmp_path, capsys):
    source = tmp_path / "in.csv"
    source.write_text("He,Sh,Br,Wa,Hi,name\n160,40,95,80,105,a\n170,42,100,85,110,b\n", encoding="utf-8")
    code, _, _ = run(
        ["batch", str(source), "-o", str(tmp_path / "out"), "--format", "json,mjcf,obj", "--pose", "t_pose"], capsys
    )
    assert code == 0
    for name in "ab":
        assert read_pose(tmp_path / "out" / f"{name}.json")[0].name == "t_pose"
        text = (tmp_path / "out" / f"{name}.xml").read_text()
        assert '<key name="t_pose"' in text and "<freejoint" in text
        obj = (tmp_path / "out" / f"{name}.obj").read_text()
        assert obj.count("\no ") == 40  # every ellipsoid, as no --cushions


@pytest.mark.parametrize("references", [FEMALE_SET, FEMALE_FINE_SET])
def test_posed_obj_with_cushions_has_the_split_halves(tmp_path, capsys, references):
    rest = tmp_path / "rest.json"
    assert run(["synth", *REQUEST, "--references", references, "-o", str(rest)], capsys)[0] == 0
    out = tmp_path / "t.obj"
    code, _, _ = run(["pose", str(rest), "--pose", "t_pose", "--cushions", "-o", str(out)], capsys)
    assert code == 0
    names = [line[2:] for line in out.read_text().splitlines() if line.startswith("o ")]
    assert "3.a Upper Arm.L + 3.b Forearm.L (3.b Forearm.L)" in names and "5.a Thigh.L + 5.b Knee.L" in names
    topology = Mannequin.load(rest).topology
    pairs, split = len(topology.cushion_pairs), len(cross_joint_pairs(topology))
    assert "3.a Upper Arm.L" not in names and len(names) == len(topology) - 2 * pairs + pairs + split


def _no_joints(tmp_path, rest):
    data = json.loads(rest.read_text())
    del data["joints"]
    old = tmp_path / "old.json"
    old.write_text(json.dumps(data))
    return old


def _beyond(tmp_path, rest):
    pose = tmp_path / "kick.json"
    pose.write_text(json.dumps({"name": "kick", "euler_xyz_degrees": {"L_Hip": [-170, 0, 0]}}))
    return pose


@pytest.mark.parametrize(
    "argv, words",
    [
        (["pose", "{rest}", "--pose", "dance", "-o", "{tmp}/x.json"], ["unknown pose 'dance'", "t_pose"]),
        (["synth", *REQUEST, "--pose", "dance", "-o", "{tmp}/x.json"], ["unknown pose 'dance'"]),
        (["pose", "{old}", "--pose", "sit", "-o", "{tmp}/x.json"], ["has no joints"]),
        (["pose", "{rest}", "--pose", "{kick}", "-o", "{tmp}/x.xml"], ["L_Hip", "-170.0", "range -140 to 20"]),
        (["pose", "{rest}", "--pose", "walk", "-o", "{tmp}/x.obj"], ["walk is an animation", ".obj"]),
        (["batch", "{tmp}/in.csv", "-o", "{tmp}/out", "--format", "obj", "--pose", "walk"], ["animation"]),
        (["pose", "{rest}", "-o", "{tmp}/x.json"], ["--pose is required"]),
    ],
)
def test_bad_poses_are_refused_in_one_line_and_nothing_is_written(tmp_path, rest, capsys, argv, words):
    (tmp_path / "in.csv").write_text("He,Sh,Br,Wa,Hi\n165,41.5,101.25,82.75,117.5\n", encoding="utf-8")
    fields = dict(rest=rest, tmp=tmp_path, old=_no_joints(tmp_path, rest), kick=_beyond(tmp_path, rest))
    before = sorted(p.name for p in tmp_path.iterdir())
    code, _, err = run([a.format(**fields) for a in argv], capsys)
    assert_one_line_error(code, err, *words)
    assert sorted(p.name for p in tmp_path.iterdir()) == before
