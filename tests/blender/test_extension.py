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
