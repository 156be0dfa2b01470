"""Every benchmark runs (``make bench`` is run by hand, rarely: a function it calls that moved or changed must fail
a test, not the benchmark a user tries): each numpy-only one's quick mode here (a few requests, one repetition, no
older commit checked out), those that need the bpy module in tests/blender/test_bench_quick_blender.py. Their figures
are not checked: speed is measured by ``make bench``, never asserted."""

import importlib
import inspect
import pathlib

import pytest

from bench.__main__ import BENCHES, NEEDS_BLENDER

BENCH = pathlib.Path(__file__).resolve().parents[2] / "bench"
NUMPY_ONLY = {  # name: slow (more than a few seconds in quick mode)
    "bench_core": False,
    "bench_exact_population": False,
    "bench_male": False,
    "bench_pose": False,
    "bench_skin": False,
    "bench_skin_posing": False,
    "bench_batch": False,
    "bench_skin_batch": True,
    "bench_references": True,  # three bodies fitted: about a minute
    "bench_scan": True,
    "bench_scan_held_out": True,
    "bench_extra": True,
    "bench_skin_exact": True,
    "bench_body_skin": False,
    "bench_body_space": True,
}


def test_every_benchmark_runs_in_make_bench_and_has_a_quick_mode_run_by_a_test():
    modules = {path.stem for path in BENCH.glob("bench_*.py")}
    assert set(BENCHES) == modules
    assert set(NUMPY_ONLY) | set(NEEDS_BLENDER) == modules and not set(NUMPY_ONLY) & set(NEEDS_BLENDER)
    for name in modules:
        assert "quick" in inspect.signature(importlib.import_module(f"bench.{name}").run).parameters, name


@pytest.mark.parametrize(
    "name", [pytest.param(name, marks=[pytest.mark.slow] if slow else []) for name, slow in NUMPY_ONLY.items()]
)
def test_the_benchmark_runs_in_its_quick_mode(name, capsys):
    result = importlib.import_module(f"bench.{name}").run(quick=True)
    out = capsys.readouterr().out
    assert out.strip() and "skipped" not in out and "no figures" not in out and "Traceback" not in out, out
    if name in ("bench_batch", "bench_skin_batch"):  # the exit codes of the batches it ran
        assert result and set(result) == {0}, out
