"""Shared fixtures for core and Blender tests, and the matrix's quick suites."""

import os
import pathlib

import pytest

from devkit.toy import make_toy_mannequin


@pytest.fixture
def toy():
    return make_toy_mannequin()


def pytest_collection_modifyitems(config, items):
    """Leave out the tests marked slow of the suites (tests/<suite>) named in ELLIMANN_QUICK_SUITES: the matrix
    (tools/matrix/lanes.py) runs them on another lane."""
    quick = {name for name in os.environ.get("ELLIMANN_QUICK_SUITES", "").split(",") if name}
    if not quick:
        return
    tests = pathlib.Path(__file__).resolve().parent
    kept, left = [], []
    for item in items:
        suite = pathlib.Path(str(item.fspath)).resolve().relative_to(tests).parts[0]
        (left if suite in quick and item.get_closest_marker("slow") else kept).append(item)
    if left:
        config.hook.pytest_deselected(items=left)
        items[:] = kept
