"""The test matrix covers what the manifest promises, and the shipped .blend files open on all of it."""

import os
import pathlib
import re
import subprocess
import sys
import tomllib

import pytest

from tools.matrix import lanes as matrix
from tools.shipped.reference_blends import FOLDER, STEMS

REPO = pathlib.Path(__file__).resolve().parents[3]
ZSTD_MAGIC = b"\x28\xb5\x2f\xfd"


def manifest_minimum():
    with open(REPO / "blender_manifest.toml", "rb") as stream:
        return tuple(int(p) for p in tomllib.load(stream)["blender_version_min"].split("."))


def lane_version(lane):
    pin = next(p for p in lane.pins if p.startswith("bpy=="))
    return tuple(int(p) for p in pin.removeprefix("bpy==").split("."))


def test_the_oldest_lane_is_the_manifests_minimum_and_the_lanes_run_oldest_first():
    versions = [lane_version(lane) for lane in matrix.LANES]
    assert versions == sorted(versions)
    assert versions[0][:2] == manifest_minimum()[:2]
    assert all(lane.blender == f"{v[0]}.{v[1]}" for lane, v in zip(matrix.LANES, versions))


def test_core_runs_on_each_numpy_major_tools_once_and_blender_on_every_lane():
    majors = {}
    for lane in matrix.LANES:
        numpy = next(p for p in lane.pins if p.startswith("numpy=="))
        majors.setdefault(numpy.removeprefix("numpy==").split(".")[0], set()).update(lane.suites)
        assert "blender" in lane.suites
    assert set(majors) == {"1", "2"}
    assert all({"core", "blender"} <= suites for suites in majors.values())
    assert sum("tools" in lane.suites for lane in matrix.LANES) == 1


def test_the_command_line_s_blender_free_suite_runs_where_the_core_runs_and_as_quick():
    assert matrix.SUITES["cli"] == "tests/cli"
    for lane in matrix.LANES:
        assert ("cli" in lane.suites) == ("core" in lane.suites), lane.blender
        assert ("cli" in lane.quick) == ("core" in lane.quick), lane.blender


def test_every_suite_s_slow_tests_run_on_some_lane_and_the_blender_ones_on_the_oldest_and_newest():
    for suite in matrix.SUITES:
        assert any(suite in lane.suites and suite not in lane.quick for lane in matrix.LANES), suite
    for lane in matrix.LANES:
        assert set(lane.quick) <= set(lane.suites)
    assert "blender" not in matrix.LANES[0].quick and "blender" not in matrix.LANES[-1].quick


def test_a_quick_suite_leaves_out_its_slow_tests_only(tmp_path):
    tests = pathlib.Path(__file__).resolve().parents[2]
    command = [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "--collect-only", "-q"]
    paths = [str(tests / "core" / "skin" / "test_skin.py"), str(tests / "tools" / "matrix" / "test_matrix.py")]

    def collected(quick, *options):
        env = {**os.environ, matrix.QUICK_VARIABLE: quick}
        out = subprocess.run([*command, *options, *paths], capture_output=True, text=True, env=env, cwd=tests.parent)
        return {line for line in out.stdout.splitlines() if "::" in line}

    everything, quick, slow = collected(""), collected("core"), collected("", "-m", "slow")
    slow_core = {item for item in slow if item.startswith("tests/core")}
    assert slow_core and everything - quick == slow_core  # the tools suite's slow tests stay


def blend_header_version(path):
    """Blender's version in a .blend file's header ('BLENDER-v402' in 4.x files, 'BLENDER17-01v0500' in
    the format Blender 5.0 introduced), through zstd when the file is compressed."""
    data = path.read_bytes()
    if data.startswith(ZSTD_MAGIC):
        zstandard = pytest.importorskip("zstandard", reason="bpy's wheels bring zstandard")
        data = zstandard.ZstdDecompressor().stream_reader(data).read(32)
    found = re.match(rb"BLENDER(?:[-_][vV]|\d\d-\d\d[vV])(\d{3,4})", data)
    assert found, f"{path.name} has no .blend header"
    return int(found.group(1))


@pytest.mark.parametrize("stem", STEMS)
def test_shipped_blends_are_saved_by_the_oldest_supported_blender(stem):
    # A file saved by a newer Blender does not open in an older one (5.0 files not at all in 4.x):
    # tools/shipped/reference_blends.py writes them on the oldest lane.
    major, minor = manifest_minimum()[:2]
    assert blend_header_version(FOLDER / f"{stem}.blend") == major * 100 + minor


def test_a_5_0_header_is_read_as_such(tmp_path):
    path = tmp_path / "new.blend"
    path.write_bytes(b"BLENDER17-01v0500REND" + bytes(12))
    assert blend_header_version(path) == 500


JUNIT = """<?xml version="1.0" encoding="utf-8"?><testsuites name="pytest tests">
<testsuite name="pytest" errors="{e}" failures="{f}" skipped="{s}" tests="{t}" time="1.0"></testsuite></testsuites>"""


def test_lane_counts_come_from_pytests_junit_report(tmp_path):
    report = tmp_path / "lane.xml"
    report.write_text(JUNIT.format(e=1, f=2, s=3, t=20))
    assert matrix._counts(report) == (14, 3, 3)
    assert matrix._counts(tmp_path / "missing.xml") is None
    report.write_text("<testsuites")
    assert matrix._counts(report) is None


def test_unknown_lanes_are_refused_by_name(capsys):
    with pytest.raises(SystemExit):
        matrix.main(["--lanes", "4.2,9.9", "--list"])
    assert "9.9" in capsys.readouterr().err


def test_list_names_every_lanes_pins(capsys):
    assert matrix.main(["--list"]) == 0
    out = capsys.readouterr().out
    assert all(pin in out for lane in matrix.LANES for pin in lane.pins)


def test_the_blender_lanes_do_not_start_without_the_gltf_validator(monkeypatch, capsys):
    from devkit import gltf_validator

    def unavailable():
        raise gltf_validator.ValidatorUnavailableError("npm is not on PATH")

    monkeypatch.setattr(gltf_validator, "module_dir", unavailable)
    assert matrix.main(["--setup-only", "--lanes", "4.2"]) == 1
    assert "matrix: npm is not on PATH" in capsys.readouterr().err


def test_lanes_side_by_side_share_the_cores_blas_threads_unless_set(monkeypatch):
    for name in matrix.BLAS_THREADS:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("PYTHONPATH", "/elsewhere")
    env = matrix._lane_env(1)
    assert all(env[name] == "1" for name in matrix.BLAS_THREADS) and "PYTHONPATH" not in env
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "4")  # the user's own choice stays
    assert matrix._lane_env(1)["OPENBLAS_NUM_THREADS"] == "4"
    assert "OMP_NUM_THREADS" not in matrix._lane_env()


def test_one_lane_runs_on_an_old_blas_kernel_unless_one_is_set(monkeypatch):
    monkeypatch.delenv("OPENBLAS_CORETYPE", raising=False)
    kernels = {lane.blender: lane.kernel for lane in matrix.LANES}
    assert kernels["5.3"] == matrix.OLD_KERNEL and kernels["5.0"] == ""  # the core suite runs on each
    assert matrix._lane_env(1, matrix.OLD_KERNEL)["OPENBLAS_CORETYPE"] == matrix.OLD_KERNEL
    assert "OPENBLAS_CORETYPE" not in matrix._lane_env(1)
    monkeypatch.setenv("OPENBLAS_CORETYPE", "Haswell")
    assert matrix._lane_env(1, matrix.OLD_KERNEL)["OPENBLAS_CORETYPE"] == "Haswell"


def test_no_two_test_files_share_a_name():
    """A lane runs tests/core and tests/blender in one pytest, which imports test files by their base name."""
    tests = pathlib.Path(__file__).resolve().parents[2]
    names = [path.name for path in tests.rglob("test_*.py")]
    assert sorted({name for name in names if names.count(name) > 1}) == []
