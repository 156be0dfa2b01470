"""The Khronos glTF validator (npm ``gltf-validator``) for tests: installed into ``out/node`` with npm (pinned),
by ``tools.matrix`` before its lanes start (``make test``, CI) or else on first use (one install at a time), run
with node. No node or npm, or a failed install: ValidatorUnavailableError, so the tests fail (never skip).

``validate(path)`` returns the validator's issues: ``{"numErrors", "numWarnings", "numInfos", "numHints",
"messages": [{"code", "message", "severity", "pointer"}, ...]}``. Needs ``node`` and ``npm`` on PATH (CI
machines: Node.js 18 or newer) and, the first time, network access to the npm registry.
"""

import fcntl
import json
import pathlib
import shutil
import subprocess

REPO = pathlib.Path(__file__).resolve().parents[1]
PREFIX = REPO / "out" / "node"
PACKAGE = "gltf-validator"
VERSION = "2.0.0-dev.3.10"
SCRIPT = pathlib.Path(__file__).with_name("gltf_validate.js")


class ValidatorUnavailableError(RuntimeError):
    """node or npm is missing, or npm could not install the validator."""


def module_dir():
    """The installed validator's folder, installing it first if it is not there (or another version is)."""
    target = PREFIX / "node_modules" / PACKAGE
    if _installed_version(target) == VERSION:
        return target
    npm = shutil.which("npm")
    if npm is None:
        raise ValidatorUnavailableError(
            "npm is not on PATH: install Node.js 18+ (the glTF tests run the Khronos validator)"
        )
    PREFIX.mkdir(parents=True, exist_ok=True)
    with open(PREFIX / ".install.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if _installed_version(target) != VERSION:
            done = subprocess.run(
                [
                    npm,
                    "install",
                    "--prefix",
                    str(PREFIX),
                    "--no-audit",
                    "--no-fund",
                    "--loglevel=error",
                    f"{PACKAGE}@{VERSION}",
                ],
                capture_output=True,
                text=True,
            )
            if done.returncode != 0 or _installed_version(target) != VERSION:
                raise ValidatorUnavailableError(
                    f"npm could not install {PACKAGE}@{VERSION}: {done.stderr.strip()[-400:]}"
                )
    return target


def _installed_version(target):
    try:
        return json.loads((target / "package.json").read_text())["version"]
    except (OSError, ValueError, KeyError):
        return None


def validate(path):
    """The validator's issues for a .glb / .gltf file (see the module docstring)."""
    node = shutil.which("node")
    if node is None:
        raise ValidatorUnavailableError(
            "node is not on PATH: install Node.js 18+ (the glTF tests run the Khronos validator)"
        )
    done = subprocess.run([node, str(SCRIPT), str(module_dir()), str(path)], capture_output=True, text=True)
    if done.returncode != 0:
        raise ValidatorUnavailableError(f"the glTF validator failed on {path}: {done.stderr.strip()[-400:]}")
    return json.loads(done.stdout)


def errors(issues):
    """The messages of severity 0 (errors)."""
    return [m for m in issues["messages"] if m["severity"] == 0]


if __name__ == "__main__":  # python3 -m devkit.gltf_validator: install it now (tools.matrix does, before the lanes)
    print(f"glTF validator {VERSION} in {module_dir()}")
