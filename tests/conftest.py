"""Shared fixtures for core and Blender tests."""

import pytest

from devkit.toy import make_toy_mannequin


@pytest.fixture
def toy():
    return make_toy_mannequin()
