"""Blender tests on the bpy module: user folders in a temp dir, add-on registered once, empty file per test."""

import os
import tempfile

# Must be set before bpy is imported so nothing touches the machine's Blender configuration.
os.environ["BLENDER_USER_RESOURCES"] = tempfile.mkdtemp(prefix="ellimann-blender-user-")

import bpy  # noqa: E402
import pytest  # noqa: E402

import ellimann_addon  # noqa: E402
from devkit.blender_scene import parts  # noqa: E402
from ellimann_addon.blender.bridge.convert import mannequin_to_collection  # noqa: E402


@pytest.fixture(scope="session", autouse=True)
def addon():
    ellimann_addon.register()
    yield
    ellimann_addon.unregister()


@pytest.fixture(autouse=True)
def empty_file():
    bpy.ops.wm.read_homefile(use_empty=True)
    yield


@pytest.fixture
def toy_collection(toy):
    """The toy mannequin as a collection, with its first ellipsoid active and nothing selected."""
    collection = mannequin_to_collection(toy)
    bpy.context.view_layer.objects.active = parts(collection)["1.a Head"]
    return collection


@pytest.fixture(autouse=True)
def no_settle_timer_left():
    """Live updates leave the settle timers (the cushions', the skin's) registered; they must not fire in a later
    test."""
    yield
    from ellimann_addon.blender.features.skin import live as skin_live
    from ellimann_addon.blender.features.synthesize import live

    for timer in (live._settle_timer, skin_live._settle_timer):
        if bpy.app.timers.is_registered(timer):
            bpy.app.timers.unregister(timer)


_exit_status = {}


def pytest_sessionfinish(session, exitstatus):
    _exit_status["code"] = int(exitstatus)


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config):
    # Blender 4.x as a module segfaults in its own teardown after the tests have run and reported
    # (ellimann_addon/blender/services/teardown.py): leave with pytest's own exit status instead.
    from ellimann_addon.blender.services import teardown

    if teardown.needs_workaround() and "code" in _exit_status:
        teardown.exit_without_teardown(_exit_status["code"])
