"""Running the command line in tests: in-process (``run``) or as ``python -m ellimann_addon`` (``python_m``),
and the check every refused input shares (one line on stderr, exit 1, no traceback)."""

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
