"""Running the command line in tests: in-process (``run``), as ``python -m ellimann_addon`` (``python_m``) or so with
the bpy module blocked (``without_blender``), and the check every refused input shares (one line on stderr, exit 1,
no traceback)."""

import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]


def run(args, capsys):
    """``cli.main(args)`` in this process: (exit code, stdout, stderr)."""
    from ellimann_addon import cli

    code = cli.main(args)
    out, err = capsys.readouterr()
    return code, out, err


def python_m(*args, cwd=ROOT):
    """``python -m ellimann_addon ARGS`` in a subprocess, with the test session's Blender user folders."""
    return subprocess.run(
        [sys.executable, "-m", "ellimann_addon", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        env=dict(os.environ, BLENDER_USER_RESOURCES=os.environ["BLENDER_USER_RESOURCES"]),
        timeout=300,
    )


def assert_one_line_error(code, err, *words):
    assert code == 1
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    for word in words:
        assert word in lines[0], lines[0]


# Runs the CLI as ``python -m ellimann_addon`` does (its __main__) with Blender's modules blocked, and reports on
# stderr's last line which ElliMann modules of the bpy layer were imported (tests/cli/test_cli_without_blender.py
# tests that the blocker blocks).
WITHOUT_BLENDER = """
import atexit, runpy, sys
class NoBlender:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in ("bpy", "bmesh", "mathutils", "bpy_extras", "gpu"):
            raise ImportError(f"No module named {name!r} (blocked by the test)")
        return None
sys.meta_path.insert(0, NoBlender())
def report():
    loaded = sorted(m for m in sys.modules if m == "bpy" or m.startswith("ellimann_addon.blender"))
    print("LOADED", loaded, file=sys.stderr)
atexit.register(report)
sys.argv = ["ellimann", *sys.argv[1:]]
runpy.run_module("ellimann_addon", run_name="__main__", alter_sys=True)
"""


def without_blender(*args, cwd=ROOT):
    """The CLI with bpy blocked, in a subprocess: (exit code, stdout, stderr without the last line); asserts that
    no module of the bpy layer was imported."""
    done = subprocess.run(
        [sys.executable, "-c", WITHOUT_BLENDER, *args], cwd=cwd, capture_output=True, text=True, timeout=300
    )
    *lines, loaded = done.stderr.strip().splitlines()
    assert loaded == "LOADED []", done.stderr
    return done.returncode, done.stdout, "\n".join(lines)
