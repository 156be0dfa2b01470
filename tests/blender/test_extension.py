"""The extension zip: built and validated by Blender's own tool, installed, used, disabled, enabled.

The installed copy runs in a fresh Python process with its own user folder, so it cannot clash
with the in-tree add-on this test session registered.
"""

import json
import os
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import bpy
import pytest

ROOT = Path(__file__).resolve().parents[2]
EXT_TOOL = Path(bpy.utils.system_resource("SCRIPTS")) / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"


def run(*args, **kwargs):
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "BLENDER_USER_RESOURCES")}
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, env=env, **kwargs)


@pytest.fixture(scope="module")
def built_zip(tmp_path_factory):
    version = tomllib.loads((ROOT / "blender_manifest.toml").read_text())["version"]
    path = tmp_path_factory.mktemp("dist") / f"ellimann-{version}.zip"
    build = run(EXT_TOOL, "build", "--source-dir", ROOT, "--output-filepath", path)
    assert build.returncode == 0, build.stdout + build.stderr
    return path


def test_zip_passes_blenders_validator_and_ships_only_the_add_on(built_zip):
    validate = run(EXT_TOOL, "validate", built_zip)
    assert validate.returncode == 0 and "Success" in validate.stdout, validate.stdout + validate.stderr
    names = zipfile.ZipFile(built_zip).namelist()
    assert "blender_manifest.toml" in names and "__init__.py" in names
    assert "ellimann_addon/blender/features/trace/operators.py" in names
    assert "ellimann_addon/core/measure/tailor.py" in names
    assert "ellimann_addon/core/synthesis/populations/ansur2_female.json" in names
    for folder in ("", "male/", "female-fine/", "male-fine/"):  # every shipped set, without its .blend twins
        assert (
            f"reference_blends/{folder}average.json" in names and f"reference_blends/{folder}average.blend" not in names
        )
    shipped_tops = {name.split("/")[0] for name in names}
    assert shipped_tops <= {
        "blender_manifest.toml",
        "__init__.py",
        "README.md",
        "LICENSE",
        "ellimann_addon",
        "reference_blends",
    }, shipped_tops
    assert not [n for n in names if "__pycache__" in n or n.endswith(".pyc")]


def test_installed_extension_works_and_disables_cleanly(built_zip, tmp_path):
    result = run(Path(__file__).with_name("installed_extension.py"), built_zip, tmp_path / "user", cwd=tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    report = json.loads(result.stdout.strip().splitlines()[-1])
    assert report["in_tree_importable"] is False  # really the installed copy
    assert report["install"] == ["FINISHED"] and report["enabled"] is True
    assert report["operator_module"].startswith("bl_ext.user_default.ellimann.")
    assert report["first_use"] == report["second_use"] == [[["FINISHED"]] * 3, 60.0]
    assert report["after_disable"] == [] and report["after_second_disable"] == []
    assert "Traceback" not in result.stderr and "Error" not in result.stdout


# The README's headless route, through the handler behind ``blender --command extension`` (the bpy module has no
# ``blender`` executable), in one process; then a fresh one, as the next Blender session.
INSTALL_HEADLESS = """
import os, sys
os.environ["BLENDER_USER_RESOURCES"] = sys.argv[2]
import bpy
from bl_pkg import bl_extension_cli
code = bl_extension_cli.cli_extension_handler(["install-file", "-r", "user_default", "-e", sys.argv[1]])
from bl_ext.user_default.ellimann.ellimann_addon.blender.services import teardown
teardown.exit_with(code)
"""
FRESH_SESSION = """
import json, os, sys
os.environ["BLENDER_USER_RESOURCES"] = sys.argv[1]
import bpy
if bpy.app.version >= (4, 5, 0):
    bpy.ops.wm.read_userpref()  # Blender reads them at start; a script on the bpy module must ask (README)
else:
    bpy.ops.preferences.addon_enable(module="bl_ext.user_default.ellimann")  # 4.2's read_userpref crashes (README)
print(json.dumps([
    "bl_ext.user_default.ellimann" in bpy.context.preferences.addons,
    sorted(bpy.ops.ellimann.new_mannequin(name="Fresh")),
]))
from bl_ext.user_default.ellimann.ellimann_addon.blender.services import teardown
teardown.exit_with(0)
"""


def test_the_headless_install_enables_the_extension_for_the_next_session(built_zip, tmp_path):
    user = tmp_path / "user"
    installed = run("-c", INSTALL_HEADLESS, built_zip, user, cwd=tmp_path)
    assert installed.returncode == 0, installed.stdout + installed.stderr
    assert (user / "config" / "userpref.blend").is_file()  # -e enabled it and saved the preferences
    fresh = run("-c", FRESH_SESSION, user, cwd=tmp_path)
    assert fresh.returncode == 0, fresh.stdout + fresh.stderr
    assert json.loads(fresh.stdout.strip().splitlines()[-1]) == [True, ["FINISHED"]]
