"""``batch --skin``: rows per second per core with the body skin (the set's bodies, docs/body_skin.md: exact on the
skin whatever the mode) and with the skin over the pieces at the preview (10 mm) and final (5 mm) levels, in IDW
and exact mode (the pieces refined until the skin measures the request), against the same batch without a skin in
the same run; and the peak memory at a few rows and at more (a skin is made per row and
dropped: it must not grow with the rows).

Rows: ``ellimann population --stats ansur2_female --seed 1`` (the first N). Each batch runs in a child process
(``python -m ellimann_addon batch ... --format obj,json``) started by a small launcher that reports the child's
CPU time (user + system: one core's work, whatever else the machine runs) and peak resident memory (``os.wait4``).
A row's cost is the difference between a batch of N rows and one of 1, over N - 1 (the start-up, reading the
reference set and numpy's imports, cancels out); rows/s per core is its inverse.

    python -m bench.bench_skin_batch                 # 3 rows (and 1) per configuration
    python -m bench.bench_skin_batch --rows 6
"""

import argparse
import itertools
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
CONFIGURATIONS = (  # (label, batch options)
    ("no skin, exact", ["--mode", "exact"]),
    ("body, exact", ["--mode", "exact", "--skin", "--skin-kind", "body"]),
    ("body, idw", ["--mode", "idw", "--skin", "--skin-kind", "body"]),
    ("preview, idw", ["--mode", "idw", "--skin", "--skin-level", "preview"]),
    ("final, idw", ["--mode", "idw", "--skin", "--skin-level", "final"]),
    ("preview, exact", ["--mode", "exact", "--skin", "--skin-level", "preview"]),
    ("final, exact", ["--mode", "exact", "--skin", "--skin-level", "final"]),
)
# A child of its own reports the batch's rusage (see bench_batch: a process started straight from this one would
# count this one's memory in its peak).
LAUNCHER = """
import os, subprocess, sys, time
start = time.perf_counter()
child = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
_, status, usage = os.wait4(child.pid, 0)
print(time.perf_counter() - start, usage.ru_utime + usage.ru_stime, usage.ru_maxrss, os.waitstatus_to_exitcode(status))
"""


def people(folder, rows):
    """CSVs of the first 1 and ``rows`` sampled people (ANSUR II female statistics, seed 1)."""
    source = folder / "people.csv"
    command = [sys.executable, "-m", "ellimann_addon", "population", "--stats", "ansur2_female", "--seed", "1"]
    subprocess.run([*command, "--n", str(rows), "-o", str(source)], cwd=ROOT, check=True, capture_output=True)
    paths = {}
    for count in (1, rows):
        paths[count] = folder / f"people-{count}.csv"
        with source.open() as lines, paths[count].open("w") as prefix:
            prefix.writelines(itertools.islice(lines, count + 1))
    return paths


def measured_batch(csv_path, out, options):
    """(wall s, CPU s, peak bytes, exit code) of one batch in a child process."""
    shutil.rmtree(out, ignore_errors=True)
    command = [sys.executable, "-m", "ellimann_addon", "batch", str(csv_path), "-o", str(out), "--format", "obj,json"]
    done = subprocess.run(
        [sys.executable, "-c", LAUNCHER, *command, *options, "-q"], cwd=ROOT, capture_output=True, text=True
    )
    wall, cpu, kilobytes, code = done.stdout.split()
    return float(wall), float(cpu), int(kilobytes) * 1024, int(code)  # Linux gives ru_maxrss in KiB


def run(rows=3, quick=False):
    """``quick``: 2 rows, the batch without a skin and with the body skin only (checks that it runs); returns the
    exit codes."""
    configurations = CONFIGURATIONS[:2] if quick else CONFIGURATIONS
    rows = 2 if quick else rows
    codes = []
    folder = pathlib.Path(tempfile.mkdtemp(prefix="ellimann-bench-skin-batch-"))
    try:
        paths = people(folder, rows)
        print(
            f"batch --format obj,json, ANSUR II female seed 1, 1 and {rows} rows; "
            f"{os.cpu_count()} cores, load {_load()}"
        )
        print(
            f"{'configuration':<16} {'CPU s/row':>9} {'rows/s/core':>11} {'x no skin':>9} {'wall s/row':>10} "
            f"{'peak GB 1':>9} {f'peak GB {rows}':>10} {'exit':>5}"
        )
        baseline = None
        for label, options in configurations:
            one = measured_batch(paths[1], folder / "out", options)
            many = measured_batch(paths[rows], folder / "out", options)
            codes += [one[3], many[3]]
            cpu = (many[1] - one[1]) / (rows - 1)
            wall = (many[0] - one[0]) / (rows - 1)
            baseline = baseline or cpu
            print(
                f"{label:<16} {cpu:>9.2f} {1.0 / cpu:>11.3f} {cpu / baseline:>9.0f} {wall:>10.2f} "
                f"{one[2] / 1e9:>9.3f} {many[2] / 1e9:>10.3f} {many[3]:>5}"
            )
        print("exit 3: exact mode on the skin missed a row's request by more than 1 mm (the files are written)")
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return codes


def _load():
    try:
        return " ".join(f"{v:.1f}" for v in os.getloadavg())
    except OSError:
        return "?"


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rows", type=int, default=3, help="rows per configuration (and a batch of 1): at least 2")
    arguments = parser.parse_args()
    run(max(2, arguments.rows))
