"""Bad BVH clips: each refused in one line that names the file (and the line where there is one) and what is
wrong, before anything is computed; on the command line nothing is written."""

import re

import numpy as np
import pytest

from devkit import bvh, clips
from devkit.cli_runs import assert_one_line_error, run
from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.formats.bvh import bytes_needed, read_bvh
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    joints = Mannequin.load(REFERENCE_FOLDER / "average.json").joints
    path = tmp_path_factory.mktemp("good") / "good.bvh"
    return bvh.write_bvh(path, clips.convention_clip("lafan1", joints, frames=3)).read_text()


def motion_lines(text):
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("Frame Time")) + 1
    return lines, start


def truncated(text):
    lines, start = motion_lines(text)
    return "\n".join(lines[:-1]) + "\n"


def cut_in_hierarchy(text):
    return "\n".join(text.splitlines()[:20]) + "\n"


def replace_value(value):
    def change(text):
        lines, start = motion_lines(text)
        words = lines[start + 1].split()
        words[7] = value
        lines[start + 1] = " ".join(words)
        return "\n".join(lines) + "\n"

    return change


def short_frame(text):
    lines, start = motion_lines(text)
    lines[start + 1] = " ".join(lines[start + 1].split()[:-1])
    return "\n".join(lines) + "\n"


def extra_frame(text):
    lines, start = motion_lines(text)
    return "\n".join(lines + [lines[-1]]) + "\n"


def renamed(text):
    for i, name in enumerate(re.findall(r"(?:ROOT|JOINT) (\S+)", text)):
        text = re.sub(rf"((?:ROOT|JOINT) ){re.escape(name)}\n", rf"\1Knochen{i}\n", text)
    return text


def lying(text):
    """Every OFFSET's y and z swapped: the skeleton lies along Z."""

    def swap(match):
        x, y, z = match.group(1).split()
        return f"OFFSET {x} {z} {y}"

    return re.sub(r"OFFSET (\S+ \S+ \S+)", swap, text)


CASES = [
    (lambda t: "hello\n", r"clip bad\.bvh: is not a BVH clip \(its first word is not HIERARCHY\)"),
    (cut_in_hierarchy, r"clip bad\.bvh: ends at line 20 where .* should follow"),
    (truncated, r"clip bad\.bvh: is truncated: its MOTION has 2 frame lines of the 3 it announces"),
    (
        lambda t: t.replace("Frames: 3", "Frames: 1000000"),
        r"clip bad\.bvh: is truncated: its 1000000 frames of 69 values need at least 137999999 more bytes",
    ),
    (replace_value("abc"), r"clip bad\.bvh, line \d+: 'abc' is not a finite number"),
    (replace_value("nan"), r"clip bad\.bvh, line \d+: 'nan' is not a finite number"),
    (short_frame, r"clip bad\.bvh, line \d+: frame 2 has 68 values, its bones' channels are 69"),
    (extra_frame, r"clip bad\.bvh, line \d+: more frame lines than its Frames: 3"),
    (
        lambda t: t.replace("Zrotation", "Wrotation", 1),
        r"clip bad\.bvh, line 5: channel 'wrotation' of 'Hips' is not one of X/Y/Z position and X/Y/Z rotation",
    ),
    (
        lambda t: t.replace("Xrotation Yrotation", "Xrotation Xrotation", 1),
        r"clip bad\.bvh, line \d+: channel 'xrotation' of 'Hips' repeats X/Y/Z position and X/Y/Z rotation",
    ),
    (lambda t: t.replace("OFFSET", "OFSET", 1), r"clip bad\.bvh, line 4: expected OFFSET, got 'OFSET'"),
    (lambda t: t.replace("Frame Time: 0.033333", "Frame Time: 0"), r"Frame Time must be positive, got 0"),
    (lambda t: t.replace("Frames: 3", "Frames: 0"), r"Frames must be a whole number of at least 1, got 0"),
    (renamed, r"bones: no limb recognised among the 22 bones of bad\.bvh \(Knochen0, Knochen1, "),
    (lying, r"clip bad\.bvh: its rest skeleton does not stand up along Y, BVH's up axis \(it spans "),
]


@pytest.mark.parametrize("change, message", CASES, ids=[m[:40] for _, m in CASES])
def test_a_bad_clip_is_refused_in_one_line(good, tmp_path, change, message):
    path = tmp_path / "bad.bvh"
    path.write_text(change(good))
    with pytest.raises(ElliMannError) as refused:
        read_bvh(path)
    assert re.search(message, str(refused.value)) and "\n" not in str(refused.value), str(refused.value)


def test_a_clip_too_long_for_the_memory_is_refused_from_its_header(good, tmp_path):
    path = tmp_path / "long.bvh"
    path.write_text(good)
    needed = bytes_needed(3, 69, 22)
    read_bvh(path, memory=2 * needed + 1)
    with pytest.raises(
        ElliMannError, match=r"clip long\.bvh: 3 frames of 22 bones need about 0\.2 GB to retarget, more "
    ):
        read_bvh(path, memory=2 * needed - 1)
    assert bytes_needed(10**6, 69, 22) > 3e10  # a million frames: refused on most machines


@pytest.mark.slow
def test_the_estimate_per_frame_covers_what_a_frame_takes(tmp_path):
    """What tracemalloc sees reading, retargeting and writing a clip to .json, 600 frames against 200: the
    estimate per frame is above it and within four times it."""
    average = Mannequin.load(REFERENCE_FOLDER / "average.json")
    measured, estimated = clips.bytes_per_frame("lafan1", average, tmp_path)
    assert measured < estimated < 4 * measured, (measured, estimated)


@pytest.mark.parametrize("command", ["synth", "pose"])
def test_the_command_line_refuses_a_bad_clip_in_one_line_and_writes_nothing(good, tmp_path, capsys, command):
    path = tmp_path / "bad.bvh"
    path.write_text(truncated(good))
    rest = tmp_path / "rest.json"
    Mannequin.load(REFERENCE_FOLDER / "average.json").save(rest)
    before = sorted(p.name for p in tmp_path.iterdir())
    request = ["--he", "160", "--sh", "40", "--br", "95", "--wa", "80", "--hi", "105"]
    head = ["synth", *request] if command == "synth" else ["pose", str(rest)]
    code, _, err = run([*head, "--pose", str(path), "-o", str(tmp_path / "out.json")], capsys)
    assert_one_line_error(code, err, "bad.bvh: is truncated")
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_units_are_never_guessed_from_nothing(tmp_path):
    path = tmp_path / "flat.bvh"
    path.write_text(
        "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n"
        " JOINT LeftUpLeg\n {\n  OFFSET 0 0 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n }\n}\n"
        "MOTION\nFrames: 1\nFrame Time: 0.04\n0 0 0 0 0 0\n"
    )
    with pytest.raises(ElliMannError, match="does not stand up along Y"):
        read_bvh(path)
    assert np.isfinite(bytes_needed(1, 6, 2))
