"""A batch at population scale: peak memory and time of ``ellimann batch PEOPLE.csv -o DIR --format npz`` by row
count, for this tree and (``--old DIR``) another checkout run in the same session, e.g. a ``git worktree`` of the
code before the batch streamed.

Rows: ``ellimann population --stats ansur2_female --seed 1`` (the first N rows of one draw, so every count is a
prefix of the largest). Each batch runs in a child process (``python -m ellimann_addon``, from the tree's root);
its peak resident memory is the child's ``ru_maxrss`` (``os.wait4`` in a small launcher process), its time the
wall clock. Memory flat in
the row count means the largest batch's peak within a few times the smallest's; the ratios are printed against
the first run of this tree.

    python -m bench.bench_batch                                    # 2,000 and 20,000 rows, exact mode
    python -m bench.bench_batch --rows 20000,1000000 --mode idw --old /tmp/batch-old --old-rows 20000,200000
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


def people(path, rows):
    """The CSV of ``rows`` sampled people (ANSUR II female statistics, seed 1)."""
    command = [sys.executable, "-m", "ellimann_addon", "population", "--stats", "ansur2_female", "--seed", "1"]
    subprocess.run([*command, "--n", str(rows), "-o", str(path)], cwd=ROOT, check=True, capture_output=True)
    return path


# Run in a small interpreter of its own, which starts the batch and reports the batch's rusage: a process started
# straight from this one would count this one's memory in its peak (Linux carries the memory high-water mark of the
# process image an exec replaces, and subprocess may share this process's until the exec).
LAUNCHER = """
import os, subprocess, sys, time
start = time.perf_counter()
child = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
_, status, usage = os.wait4(child.pid, 0)
print(time.perf_counter() - start, usage.ru_maxrss, os.waitstatus_to_exitcode(status))
"""


def measured_batch(tree, csv_path, out, mode):
    """(seconds, peak resident memory in bytes, exit code) of one batch run by ``tree``'s code in a child process."""
    shutil.rmtree(out, ignore_errors=True)
    command = [sys.executable, "-m", "ellimann_addon", "batch", str(csv_path), "-o", str(out), "--format", "npz"]
    done = subprocess.run(
        [sys.executable, "-c", LAUNCHER, *command, "--mode", mode, "-q"], cwd=tree, capture_output=True, text=True
    )
    seconds, kilobytes, code = done.stdout.split()
    return float(seconds), int(kilobytes) * 1024, int(code)  # Linux gives ru_maxrss in KiB


def run(rows=(2_000, 20_000), mode="exact", old=None, old_rows=None, keep=None, quick=False):
    """``quick``: 20 and 50 rows, this tree only (checks that it runs); returns the exit codes."""
    if quick:
        rows, old = (20, 50), None
    codes = []
    folder = pathlib.Path(keep or tempfile.mkdtemp(prefix="ellimann-bench-batch-"))
    folder.mkdir(parents=True, exist_ok=True)
    largest = max([*rows, *(old_rows or ())])
    source = folder / f"people-{largest}.csv"
    if not source.exists():
        people(source, largest)
    trees = [("this tree", ROOT, rows)] + ([("--old", pathlib.Path(old), old_rows or rows)] if old else [])
    print(f"batch --format npz --mode {mode}, ANSUR II female seed 1; {os.cpu_count()} cores, load {_load()}")
    print(f"{'code':<10} {'rows':>9} {'wall s':>8} {'ms/row':>7} {'peak GB':>8} {'x first':>8} {'exit':>5}")
    first = None
    try:
        for label, tree, counts in trees:
            for count in counts:
                csv_path = folder / f"people-{count}.csv"
                if not csv_path.exists():  # the first rows of the largest draw, streamed
                    with source.open() as lines, csv_path.open("w") as prefix:
                        prefix.writelines(itertools.islice(lines, count + 1))
                seconds, peak, code = measured_batch(tree, csv_path, folder / "out", mode)
                codes.append(code)
                first = first or peak
                print(
                    f"{label:<10} {count:>9,} {seconds:>8.1f} {1e3 * seconds / count:>7.3f} {peak / 1e9:>8.3f} "
                    f"{peak / first:>8.2f} {code:>5}",
                    flush=True,
                )
    finally:
        if keep is None:
            shutil.rmtree(folder, ignore_errors=True)
    print(f"load after: {_load()}")
    return codes


def _load():
    return " ".join(f"{value:.1f}" for value in os.getloadavg())


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m bench.bench_batch", description=__doc__.splitlines()[0])
    parser.add_argument("--rows", default="2000,20000", help="row counts for this tree (comma-separated)")
    parser.add_argument("--mode", default="exact", choices=("exact", "idw"))
    parser.add_argument("--old", metavar="DIR", help="another checkout's root, run in the same session")
    parser.add_argument("--old-rows", help="row counts for --old (default: --rows)")
    parser.add_argument("--keep", metavar="DIR", help="keep the CSVs and the last output here")
    args = parser.parse_args(argv)
    counts = [int(n) for n in args.rows.split(",")]
    old_counts = [int(n) for n in args.old_rows.split(",")] if args.old_rows else None
    run(counts, args.mode, args.old, old_counts, args.keep)


if __name__ == "__main__":
    main()
