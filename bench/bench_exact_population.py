"""Exact mode over a million requests sampled from a real population (issue 26: "exact mode must not miss inside
the range"): how many miss, and how fast.

Rows are drawn from the ANSUR II female statistics (``core.synthesis.population``, seed 0; the same rows on every
machine); those within the female set's ranges L are synthesized in exact mode in chunks of CHUNK
(``synthesize_batch``), and every one must converge (0.001 %). Printed: rows drawn, within L, misses (each listed,
up to a few), the largest error of any converged row, and the throughput (wall and CPU, one process).
Also the two requests the issue found missing (He 167.1, Sh 48.06 or 49.0, Br 98.98, Wa 81.81, Hi 103.24).

``python -m bench.bench_exact_population [ROWS] [--before COMMIT [--before-rows N]]`` (default 1,000,000 rows:
several minutes on one core). ``--before``: the first N (BEFORE_ROWS) of those requests also through COMMIT's code
(a temporary git worktree, a process of its own), for its misses and throughput on the same requests.
"""

import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

from ellimann_addon.core.measurements import MEASUREMENTS

ROWS = 1_000_000
SEED = 0
CHUNK = 20_000
BEFORE_ROWS = 200_000
SHOWN = 8  # misses listed
QUICK_ROWS = 500
ISSUE_REQUESTS = ((167.1, 48.06, 98.98, 81.81, 103.24), (167.1, 49.0, 98.98, 81.81, 103.24))
REPO = pathlib.Path(__file__).resolve().parents[1]


def within_ranges(rows_wanted, seed=SEED):
    """(requests within the female set's L (R, 5), rows drawn, rows accepted as bodies)."""
    from ellimann_addon.core.synthesis.population import load_population
    from ellimann_addon.core.synthesis.shipped import named_reference_set

    reference = named_reference_set("female")
    rows, accepted = load_population("ansur2_female").sample(rows_wanted, seed)
    five = rows[accepted][:, : len(MEASUREMENTS)]
    low, high = (np.array([reference.ranges[key][end] for key in MEASUREMENTS]) for end in (0, 1))
    return five[np.all((five >= low) & (five <= high), axis=1)], len(rows), int(accepted.sum())


def synthesize_all(requests, chunk=CHUNK, progress=None):
    """Exact mode over ``requests`` in chunks: a dict of figures (misses with their errors, seconds)."""
    from ellimann_addon.core.synthesis.shipped import named_reference_set
    from ellimann_addon.core.synthesis.synthesize import synthesize_batch

    reference = named_reference_set("female")
    misses, worst = [], 0.0
    wall, cpu = time.perf_counter(), time.process_time()
    for start in range(0, len(requests), chunk):
        batch = synthesize_batch(reference, requests[start : start + chunk])
        error = batch.relative_error()
        for row in np.nonzero(~batch.converged)[0]:
            misses.append([start + int(row), requests[start + row].tolist(), error[row].tolist()])
        if batch.converged.any():
            worst = max(worst, float(error[batch.converged].max()))
        if progress:
            progress(start + len(batch), len(requests), time.perf_counter() - wall)
    return {
        "requests": len(requests),
        "misses": misses,
        "worst converged %": worst,
        "wall s": time.perf_counter() - wall,
        "cpu s": time.process_time() - cpu,
    }


def show(title, figures):
    count = figures["requests"]
    print(
        f"  {title}: {count:,} requests, {len(figures['misses'])} missed; largest error of the converged "
        f"{figures['worst converged %']:.5f} %; {count / figures['wall s']:,.0f} requests/s wall, "
        f"{count / figures['cpu s']:,.0f} /s CPU ({figures['wall s']:.0f} s)"
    )
    for index, request, error in figures["misses"][:SHOWN]:
        worst = int(np.argmax(error))
        values = ", ".join(f"{value:.2f}" for value in request)
        print(f"    row {index}: {values}: {MEASUREMENTS[worst]} off by {error[worst]:.3f} %")


def before(commit, rows, count):
    """The first ``count`` requests (of ``rows`` drawn) through ``commit``'s code (a worktree and a process of its
    own): its figures."""
    with tempfile.TemporaryDirectory(prefix="ellimann-bench-exact-") as scratch:
        tree = pathlib.Path(scratch) / commit
        made = subprocess.run(
            ["git", "-C", str(REPO), "worktree", "add", "--detach", str(tree), commit], capture_output=True, text=True
        )
        if made.returncode:
            print(f"  {commit}: cannot check it out here (skipped)")
            return None
        try:
            done = subprocess.run(
                [sys.executable, str(pathlib.Path(__file__).resolve()), "--child", str(rows), str(count)],
                cwd=str(tree),
                env=dict(os.environ, PYTHONPATH=str(tree)),
                capture_output=True,
                text=True,
            )
        finally:
            subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(tree)], check=False)
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    return json.loads(lines[-1]) if lines else None


def run(rows=ROWS, commit=None, before_rows=BEFORE_ROWS, quick=False):
    """``quick``: QUICK_ROWS rows, no older commit (checks that it runs)."""
    from ellimann_addon.core.synthesis.shipped import named_reference_set

    if quick:
        rows, commit = QUICK_ROWS, None
    from ellimann_addon.core.synthesis.synthesize import synthesize_batch

    issue = synthesize_batch(named_reference_set("female"), np.array(ISSUE_REQUESTS))
    for request, converged, error in zip(ISSUE_REQUESTS, issue.converged, issue.relative_error()):
        state = "converged" if converged else "MISSED"
        print(f"  issue's request {request}: {state}, largest error {error.max():.5f} %")
    requests, drawn, bodies = within_ranges(rows)
    print(f"  ANSUR II female, seed {SEED}: {drawn:,} rows drawn, {bodies:,} plausible, {len(requests):,} within L")

    def progress(done, total, seconds):
        if done % (10 * CHUNK) == 0 or done == total:
            print(f"    {done:,} / {total:,} in {seconds:.0f} s", flush=True)

    now = synthesize_all(requests, progress=progress)
    show("now", now)
    if quick:
        return now
    if commit:
        count = min(len(requests), before_rows)
        old = before(commit, rows, count)
        if old is not None:
            show(f"{commit} (the first {old['requests']:,} of the same requests)", old)
            same = now if count == len(requests) else synthesize_all(requests[:count])
            if same is not now:
                show(f"now (the same {count:,})", same)
            print(f"  {commit} / now, CPU time on the same requests: {old['cpu s'] / same['cpu s']:.2f}x")


def child(rows, count):
    requests, _, _ = within_ranges(rows)
    figures = synthesize_all(requests[:count])
    sys.stdout.write(json.dumps(figures) + "\n")


if __name__ == "__main__":
    arguments = sys.argv[1:]
    if arguments[:1] == ["--child"]:
        child(int(arguments[1]), int(arguments[2]))
    else:

        def option(name, default):
            return arguments[arguments.index(name) + 1] if name in arguments else default

        commit, before_rows = option("--before", None), int(option("--before-rows", BEFORE_ROWS))
        named = {commit, str(before_rows)}
        numbers = [a for a in arguments if a.isdigit() and a not in named]
        run(int(numbers[0]) if numbers else ROWS, commit, before_rows)
