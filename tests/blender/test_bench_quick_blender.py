"""The benchmarks that need the bpy module run in their quick mode (tests/core/test_bench_quick.py says why; it
checks that this file's list and its own cover every benchmark)."""

import importlib

import pytest

import ellimann_addon
from bench.__main__ import NEEDS_BLENDER

SLOW = {  # name: slow (more than a few seconds in quick mode)
    "bench_synthesis": True,
    "bench_live": False,
    "bench_live_skin": True,
    "bench_drape": True,
    "bench_walk_drape": True,
    "bench_bvh": True,
    "bench_fine": True,
}


def test_this_list_is_the_benchmarks_that_need_blender():
    assert set(SLOW) == set(NEEDS_BLENDER)


@pytest.fixture
def bench_registers():
    """A benchmark registers the add-on and unregisters it when done: leave it registered as the session has it."""
    ellimann_addon.unregister()
    try:
        yield
    finally:
        ellimann_addon.register()


@pytest.mark.parametrize(
    "name", [pytest.param(name, marks=[pytest.mark.slow] if slow else []) for name, slow in SLOW.items()]
)
def test_the_benchmark_runs_in_its_quick_mode(name, capsys, bench_registers):
    result = importlib.import_module(f"bench.{name}").run(quick=True)
    out = capsys.readouterr().out
    assert out.strip() and "skipped" not in out and "no figures" not in out and "Traceback" not in out, out
    if name == "bench_live":  # each case timed in this tree's process
        assert all(result["now"][case] for case in ("ellipsoids", "cushions", "single request")), out
