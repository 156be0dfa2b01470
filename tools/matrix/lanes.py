"""The test matrix: every Blender the manifest promises, each with its own Python and numpy.

    python3 -m tools.matrix                 # every lane (what ``make test`` and CI run)
    python3 -m tools.matrix --lanes 4.2,5.3 # some of them
    python3 -m tools.matrix --list          # the lanes, their pins and suites

A lane is a virtual environment ``.venv-bpy<version>`` (Blender 5.0's is ``.venv``, the working
venv that ``make check``, ``demo``, ``bench`` and ``build`` use) made by that Blender's Python with the bpy
wheel and the numpy that Blender bundles, plus ``requirements-dev.txt``'s tools; it is made on first
use and kept (a stamp of its pins decides when to reinstall). pip's own cache is shared by every
lane, so each wheel is downloaded once. The Blender-free core and command-line (cli) suites run once per
numpy major, the tools suite once (on numpy 2), the Blender suite on every lane. Two lanes run at once (the
machines have two cores); each lane's full pytest output goes to ``out/matrix/<lane>.log`` and is printed when
the lane fails.
The last line is the whole matrix's count, ``matrix: N passed, N failed``.

Runs on the Python standard library only: it must work before any venv exists (``python3 -m tools.matrix`` runs
this module's ``main`` through the package's ``__main__.py``).
"""

import argparse
import concurrent.futures
import dataclasses
import hashlib
import os
import pathlib
import re
import shutil
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

REPO = pathlib.Path(__file__).resolve().parents[2]
REQUIREMENTS = REPO / "requirements-dev.txt"
LOGS = REPO / "out" / "matrix"

SUITES = {"core": "tests/core", "cli": "tests/cli", "tools": "tests/tools", "blender": "tests/blender"}


@dataclasses.dataclass(frozen=True)
class Lane:
    blender: str  # the lane's name: Blender's major.minor
    python: str  # the Python that Blender embeds
    pins: tuple  # the bpy wheel and the numpy Blender bundles
    suites: tuple  # which of SUITES run here
    venv_name: str = ""  # default .venv-bpy<blender>
    quick: tuple = ()  # suites whose tests marked slow this lane leaves to another lane (tests/conftest.py)
    kernel: str = ""  # OpenBLAS's kernel for this lane (OPENBLAS_CORETYPE; "" its own pick for the CPU)

    @property
    def venv(self):
        return REPO / (self.venv_name or f".venv-bpy{self.blender}")


# Oldest LTS (the manifest's minimum), newest LTS, the last Python 3.11 release, the newest release. numpy: Blender
# 4.2-5.0 bundle numpy 1.26; bpy 5.1+ wheels require numpy>=2.2,<3, of which pip takes the newest. The core runs once
# per numpy major: on 5.0 (numpy 1) and on 5.3 (numpy 2), and the command line's Blender-free suite (cli) beside it,
# treated alike; the core's tests marked slow (half its time: the skin's exact grid, the falling balls, the
# golden-section grids) run once, on 5.0, since 5.3 also carries the tools suite (the reference build, twice: some 4
# minutes), which runs once, on numpy 2: the shipped data are built on the working venv's numpy 1, so it also shows
# the build does not depend on numpy's major. The Blender suite's slow tests run on the oldest and the newest Blender.
# The newest lane runs on OpenBLAS's kernel for the first x86-64 CPUs, the others on the one it picks for this CPU
# (AVX-512's on many): every exactness test then runs under two kernels, whose last bits differ (issue 40; the same
# requests under threads, kernels and numpy's SIMD compared in tests/core/test_same_answer.py).
OLD_KERNEL = "Prescott"
LANES = (
    Lane("4.2", "3.11", ("bpy==4.2.23", "numpy==1.26.4"), ("blender",)),
    Lane("4.5", "3.11", ("bpy==4.5.15", "numpy==1.26.4"), ("blender",), quick=("blender",)),
    Lane("5.0", "3.11", ("bpy==5.0.1", "numpy==1.26.4"), ("core", "cli", "blender"), ".venv", quick=("blender",)),
    Lane(
        "5.3",
        "3.13",
        ("bpy==5.3.0", "numpy==2.5.5"),
        ("core", "cli", "tools", "blender"),
        quick=("core", "cli"),
        kernel=OLD_KERNEL,
    ),
)
QUICK_VARIABLE = "ELLIMANN_QUICK_SUITES"  # read by tests/conftest.py


def find_python(version):
    """An interpreter of this major.minor: on PATH, else from pyenv (which shims only its global one)."""
    candidate = shutil.which(f"python{version}")
    if candidate and _runs(candidate, version):
        return candidate
    pyenv_root = pathlib.Path(os.environ.get("PYENV_ROOT", pathlib.Path.home() / ".pyenv"))
    for prefix in sorted((pyenv_root / "versions").glob(f"{version}.*"), reverse=True):
        candidate = prefix / "bin" / f"python{version}"
        if candidate.is_file() and _runs(str(candidate), version):
            return str(candidate)
    raise SystemExit(
        f"matrix: no Python {version} found (on PATH as python{version} or under {pyenv_root}/versions); "
        f"the Blender lanes that embed it need one"
    )


def _runs(python, version):
    try:
        out = subprocess.run(
            [python, "-c", "import sys; print('%d.%d' % sys.version_info[:2])"],
            capture_output=True,
            text=True,
            timeout=30,
        )
    except (OSError, subprocess.TimeoutExpired):
        return False
    # pyenv's shim for a version it does not serve exits non-zero.
    return out.returncode == 0 and out.stdout.strip() == version


def _stamp(lane):
    digest = hashlib.sha256(REQUIREMENTS.read_bytes() + "\n".join(lane.pins).encode()).hexdigest()[:16]
    return lane.venv / f".installed-{digest}"


def ensure_venv(lane, log):
    """Make (or refresh) the lane's venv; returns its python. Output of the install goes to ``log``."""
    python = lane.venv / "bin" / "python"
    stamp = _stamp(lane)
    if stamp.is_file() and python.is_file():
        return python
    interpreter = find_python(lane.python)  # before anything is removed: no Python, nothing lost
    if lane.venv.is_symlink():
        lane.venv.unlink()  # a link to a venv elsewhere (a second work tree's): the venv itself stays
    elif lane.venv.exists():
        shutil.rmtree(lane.venv)  # a half-made or stale venv: pip would keep whatever else is in it
    subprocess.run([interpreter, "-m", "venv", str(lane.venv)], check=True, stdout=log, stderr=log)
    # The pins go on the same command line as the tools so that pip resolves them together: scipy or
    # mujoco may not pull in a numpy other than the one Blender bundles.
    subprocess.run(
        [str(python), "-m", "pip", "install", "--quiet", "-r", str(REQUIREMENTS), *lane.pins],
        check=True,
        stdout=log,
        stderr=log,
    )
    stamp.touch()
    return python


def run_lane(lane, extra_args, threads=None):
    LOGS.mkdir(parents=True, exist_ok=True)
    log_path, xml_path = LOGS / f"{lane.blender}.log", LOGS / f"{lane.blender}.xml"
    xml_path.unlink(missing_ok=True)
    started = time.monotonic()
    with open(log_path, "w") as log:
        try:
            python = ensure_venv(lane, log)
        except (subprocess.CalledProcessError, SystemExit, OSError) as error:
            print(f"setup failed: {error}", file=log)
            return lane, None, time.monotonic() - started, log_path
        paths = [SUITES[s] for s in lane.suites]
        # Each lane's Blender gets its own user folders (the Blender conftest makes a temp dir).
        command = [str(python), "-m", "pytest", "-p", "no:cacheprovider", f"--junitxml={xml_path}", *paths, *extra_args]
        log.write("$ " + " ".join(command) + "\n")
        log.flush()
        env = {**_lane_env(threads, lane.kernel), QUICK_VARIABLE: ",".join(lane.quick)}
        code = subprocess.run(command, cwd=REPO, stdout=log, stderr=subprocess.STDOUT, env=env).returncode
        counts = _counts(xml_path)
        if counts is not None and code != 0 and counts[1] == 0:
            # pytest said nothing failed but did not exit cleanly (a crash at exit, no test collected…)
            print(f"matrix: pytest exited with code {code} though no test failed", file=log)
            counts = (counts[0], 1, counts[2])
    return lane, counts, time.monotonic() - started, log_path


BLAS_THREADS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def _lane_env(threads=None, kernel=""):
    """The environment a lane's pytest runs in; ``threads``: the BLAS threads each lane may use, ``kernel``:
    OpenBLAS's kernel (each unless set already).

    Lanes run side by side, one per core: a BLAS that spreads a small product over every core then waits for a
    thread the other lane has the core of (the Base Mannequin's fit ran 1.7x slower beside a busy core than with
    one thread)."""
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)  # the lane's venv and the repository root only
    env.pop("VIRTUAL_ENV", None)
    if threads is not None:
        for name in BLAS_THREADS:
            env.setdefault(name, str(threads))
    if kernel:
        env.setdefault("OPENBLAS_CORETYPE", kernel)
    return env


def _counts(xml_path):
    """passed, failed (failures + errors), skipped from pytest's JUnit XML; None if it wrote none."""
    try:
        root = ET.parse(xml_path).getroot()
    except (OSError, ET.ParseError):
        return None
    suites = [root] if root.tag == "testsuite" else list(root.iter("testsuite"))
    total = sum(int(s.get("tests", 0)) for s in suites)
    failed = sum(int(s.get("failures", 0)) + int(s.get("errors", 0)) for s in suites)
    skipped = sum(int(s.get("skipped", 0)) for s in suites)
    return total - failed - skipped, failed, skipped


def versions(lane):
    """What the lane really runs (read from its venv): Blender, Python and numpy versions."""
    python = lane.venv / "bin" / "python"
    code = "import sys, numpy, bpy; print(bpy.app.version_string, '%d.%d.%d' % sys.version_info[:3], numpy.__version__)"
    out = subprocess.run([str(python), "-c", code], capture_output=True, text=True, env=_lane_env())
    return out.stdout.strip().splitlines()[-1] if out.returncode == 0 and out.stdout.strip() else "?"


def ensure_gltf_validator():
    """Install the Khronos glTF validator the Blender suite runs (``devkit.gltf_validator``: npm, into out/node)
    once, before the lanes start (they would race for it); False, saying why, if node/npm cannot."""
    from devkit import gltf_validator

    try:
        gltf_validator.module_dir()
    except gltf_validator.ValidatorUnavailableError as error:
        print(f"matrix: {error}", file=sys.stderr)
        return False
    return True


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m tools.matrix", description=__doc__.split("\n")[0])
    parser.add_argument(
        "--lanes",
        default=os.environ.get("LANES", ""),
        help="comma-separated Blender versions (default: all, or $LANES): " + ", ".join(lane.blender for lane in LANES),
    )
    parser.add_argument("--jobs", type=int, default=2, help="lanes at once (default 2)")
    parser.add_argument("--list", action="store_true", help="print the lanes and exit")
    parser.add_argument("--setup-only", action="store_true", help="make the lanes' venvs, run no test")
    args, extra = parser.parse_known_args(argv)
    extra = extra[1:] if extra[:1] == ["--"] else extra  # what follows goes to every lane's pytest
    chosen = [s.strip() for s in args.lanes.split(",") if s.strip()]
    unknown = sorted(set(chosen) - {lane.blender for lane in LANES})
    if unknown:
        parser.error(f"--lanes: unknown {', '.join(unknown)}; the lanes are {', '.join(x.blender for x in LANES)}")
    lanes = [lane for lane in LANES if not chosen or lane.blender in chosen]
    if args.list:
        for lane in lanes:
            pins = " ".join(lane.pins)
            suites = ", ".join(f"{s} (not slow)" if s in lane.quick else s for s in lane.suites)
            kernel = f"; OpenBLAS kernel {lane.kernel}" if lane.kernel else ""
            print(f"Blender {lane.blender}: Python {lane.python}, {pins}; suites {suites}{kernel}")
        return 0
    if any("blender" in lane.suites for lane in lanes) and not ensure_gltf_validator():
        return 1
    if args.setup_only:
        LOGS.mkdir(parents=True, exist_ok=True)
        for lane in lanes:
            if not _stamp(lane).is_file():
                print(f"matrix: setting up Blender {lane.blender} in {lane.venv.name} (about a minute)", flush=True)
            log_path = LOGS / f"setup-{lane.blender}.log"
            with open(log_path, "w") as log:
                try:
                    ensure_venv(lane, log)
                except (subprocess.CalledProcessError, SystemExit, OSError) as error:
                    print(f"setup failed: {error}", file=log, flush=True)
                    print(_tail(log_path), file=sys.stderr)
                    print(f"matrix: setup of Blender {lane.blender} failed", file=sys.stderr)
                    return 1
        return 0

    started = time.monotonic()
    results = []
    jobs = max(1, args.jobs)
    threads = max(1, (os.cpu_count() or 1) // jobs)  # each lane's BLAS: its share of the cores
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        # The lanes with the most suites first, so that two lanes at once finish together.
        futures = [pool.submit(run_lane, lane, extra, threads) for lane in sorted(lanes, key=lambda x: -len(x.suites))]
        for future in concurrent.futures.as_completed(futures):
            lane, counts, seconds, log_path = future.result()
            results.append((lane, counts, seconds, log_path))
            state = "setup failed" if counts is None else "{} passed, {} failed, {} skipped".format(*counts)
            print(f"matrix: Blender {lane.blender} done in {seconds:.0f} s: {state}", flush=True)
            if counts is None or counts[1]:
                print(_tail(log_path), flush=True)

    results.sort(key=lambda r: LANES.index(r[0]))
    print(f"\n{'lane':<8} {'Blender / Python / numpy':<32} {'suites':<20} {'passed':>6} {'failed':>6} {'skipped':>7}")
    for lane, counts, _, _ in results:
        p, f, s = counts if counts else ("-", "setup", "-")
        print(
            f"{lane.blender:<8} {versions(lane) if counts else '?':<32} {','.join(lane.suites):<20} "
            f"{p:>6} {f:>6} {s:>7}"
        )
    passed = sum(c[0] for _, c, _, _ in results if c)
    failed = sum(c[1] for _, c, _, _ in results if c) + sum(1 for _, c, _, _ in results if c is None)
    skipped = sum(c[2] for _, c, _, _ in results if c)
    print(f"matrix took {time.monotonic() - started:.0f} s; logs in {LOGS.relative_to(REPO)}/")
    print(f"matrix: {passed} passed, {failed} failed, {skipped} skipped")
    return 0 if failed == 0 and passed > 0 else 1


def _tail(path, lines=60):
    text = pathlib.Path(path).read_text(errors="replace").splitlines()
    # The failure summary is what a reader needs first; the log keeps the rest.
    start = next((i for i, line in enumerate(text) if re.match(r"=+ (FAILURES|ERRORS) =+", line)), None)
    chosen = text[start:] if start is not None else text[-lines:]
    return "\n".join(chosen[-400:])
