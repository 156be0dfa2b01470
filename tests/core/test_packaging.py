"""What ``pip install .`` installs: every data file the package reads is declared in pyproject.toml (a file moved
without its declaration fails here, not on a user's machine), and the wheel, installed into a fresh venv that holds
numpy and nothing else, runs each numpy-only command once."""

import fnmatch
import os
import pathlib
import shutil
import subprocess
import sys
import tomllib

import numpy as np
import pytest

from ellimann_addon import VERSION
from ellimann_addon.core.synthesis.shipped import SHIPPED_SETS

ROOT = pathlib.Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "ellimann_addon"
NOT_READ = {"README.md"}  # developers' notes beside the code: not read at run time, not installed
SETUP = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]


def package_of(folder):
    """The dotted name of the nearest package (a folder with __init__.py) at or above ``folder``, and the path from
    it."""
    here = folder
    while not (here / "__init__.py").is_file():
        here = here.parent
    return ".".join(here.relative_to(ROOT).parts), here


def declared(path):
    """Whether setuptools installs ``path`` (under ellimann_addon): a module of a package, or package data."""
    if path.suffix == ".py" and (path.parent / "__init__.py").is_file():
        return True
    name, folder = package_of(path.parent)
    relative = path.relative_to(folder).as_posix()
    return any(fnmatch.fnmatch(relative, pattern) for pattern in SETUP["package-data"].get(name, []))


def package_files():
    for path in sorted(PACKAGE.rglob("*")):
        if path.is_file() and "__pycache__" not in path.parts and path.name not in NOT_READ:
            yield path


def test_every_file_of_the_package_is_installed():
    missing = [str(path.relative_to(ROOT)) for path in package_files() if not declared(path)]
    assert not missing, f"not declared in pyproject.toml's [tool.setuptools.package-data]: {missing}"


def test_every_package_data_pattern_matches_a_file():
    """A declaration left behind when its files moved (the populations once did) matches nothing."""
    for name, patterns in SETUP["package-data"].items():
        folder = ROOT.joinpath(*name.split("."))
        assert (folder / "__init__.py").is_file(), f"{name} is not a package"
        for pattern in patterns:
            assert list(folder.glob(pattern)), f"{name}: {pattern} matches no file"


def test_the_check_can_fail(tmp_path):
    assert not declared(PACKAGE / "core" / "synthesis" / "populations" / "elsewhere.csv")
    assert declared(PACKAGE / "core" / "synthesis" / "populations" / "ansur2_female.json")


def test_every_shipped_reference_set_is_installed_where_the_code_looks():
    """core.synthesis.reference_set finds an installed set under share/ellimann/reference_blends/<its folder>."""
    data = SETUP["data-files"]
    installed = {}
    for target, patterns in data.items():
        for pattern in patterns:
            for path in ROOT.glob(pattern):
                installed[path.relative_to(ROOT).as_posix()] = target
            assert f"share/ellimann/{pathlib.PurePosixPath(pattern).parent}" == target, (target, pattern)
    for folder in SHIPPED_SETS.values():
        for path in folder.glob("*.json"):
            assert path.relative_to(ROOT).as_posix() in installed, path


SOURCES = ("pyproject.toml", "README.md", "LICENSE", "ellimann_addon")


def numpy_only_site(folder):
    """A folder holding the running numpy alone (symlinks to it and its bundled libraries), for a .pth file."""
    folder.mkdir()
    here = pathlib.Path(np.__file__).resolve().parent
    for path in here.parent.iterdir():
        if path.name == "numpy" or path.name.startswith("numpy.libs") or path.name.startswith("numpy-"):
            (folder / path.name).symlink_to(path)
    return folder


@pytest.mark.slow
def test_the_installed_wheel_runs_each_numpy_only_command(tmp_path):
    source = tmp_path / "source"
    source.mkdir()
    for name in SOURCES:
        if (ROOT / name).is_dir():
            shutil.copytree(ROOT / name, source / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy(ROOT / name, source / name)
    for pattern in (p for patterns in SETUP["data-files"].values() for p in patterns):
        for path in ROOT.glob(pattern):
            (source / path.relative_to(ROOT)).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(path, source / path.relative_to(ROOT))
    env = {key: value for key, value in os.environ.items() if not key.startswith(("PYTHON", "VIRTUAL_ENV"))}
    wheels = tmp_path / "wheels"
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(wheels), str(source)],
        check=True,
        capture_output=True,
        env=env,
        timeout=300,
    )
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, env=env, timeout=120)
    python = venv / "bin" / "python"
    site = subprocess.run(
        [python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        check=True,
        capture_output=True,
        text=True,
        env=env,
    ).stdout.strip()
    (pathlib.Path(site) / "numpy_only.pth").write_text(str(numpy_only_site(tmp_path / "numpy")) + "\n")
    wheel = next(wheels.glob("ellimann-*.whl"))
    subprocess.run(
        [python, "-m", "pip", "install", "--no-deps", "--no-index", "-q", str(wheel)],
        check=True,
        capture_output=True,
        env=env,
        timeout=300,
    )
    work = tmp_path / "work"  # not the checkout: nothing of it can be found from here
    work.mkdir()
    ellimann = str(venv / "bin" / "ellimann")

    def command(*args, code=0):
        done = subprocess.run([ellimann, *args], cwd=work, capture_output=True, text=True, env=env, timeout=300)
        assert done.returncode == code, (args, done.stdout, done.stderr)
        return done.stdout + done.stderr

    sees_bpy = subprocess.run(
        [python, "-c", "import bpy"], cwd=work, capture_output=True, text=True, env=env, check=False
    ).returncode
    assert sees_bpy != 0, "the fresh venv must not see bpy"
    assert command("--version").strip() == f"ellimann {VERSION}"
    request = ["--he", "165", "--sh", "41.5", "--br", "101.25", "--wa", "82.75", "--hi", "117.5"]
    for output in ("w.json", "w.xml", "w.obj"):
        assert "max error 0.000%" in command("synth", *request, "-o", output)
    assert "wrote m.json" in command(
        "synth",
        "--references",
        "male-fine",
        "--he",
        "180",
        "--sh",
        "52",
        "--br",
        "108",
        "--wa",
        "96",
        "--hi",
        "104",
        "-o",
        "m.json",
    )
    assert "165.00 cm" in command("measure", "w.json")
    assert "wrote 4 rows sampled from ansur2_female" in command(
        "population", "--stats", "ansur2_female", "--n", "4", "--seed", "1", "-o", "people.csv"
    )
    assert "4 of 4 mannequins written" in command("batch", "people.csv", "-o", "out", "--format", "json,npz")
    assert "wrote" in command("pose", "w.json", "--pose", "walk", "-o", "walk.json")
    for name in SHIPPED_SETS:
        assert "worst m_T error" in command("references", "check", name)
    assert "needs Blender" in command("synth", *request, "-o", "w.glb", code=1)
    assert "needs Blender" in command("demo", "-o", "demo", code=1)
