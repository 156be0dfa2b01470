"""What a skin costs at each level (``core.skin.surface.build_skin``), now against an older commit in the same run.

Each tree (this one, and ``BEFORE``: the skin as it first landed, checked out in a temporary git worktree) runs
``build_skin`` on the five Reference Mannequins of a shipped set (``--set``, default female) at the preview (10 mm)
and final (5 mm) levels in a process of its own; the trees alternate over ROUNDS rounds so that the machine's load
falls on both alike. Printed per level: the median CPU seconds of one skin (user + system of that process), the
vertices, and the older tree's median over now's. Exact mode on the skin (``exact_skin``, Table 2.5's first
request) is timed in this tree only.

``python -m bench.bench_skin [--rounds N] [--before COMMIT] [--set NAME]``
"""

import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import tempfile

from bench.bench_live import worktree

REPO = pathlib.Path(__file__).resolve().parents[1]
BEFORE = "51ecd21"  # the skin and its posing, before the field and meshing were made faster
ROUNDS = 2
LEVELS = {"preview": 10.0, "final": 5.0}

# Run inside a tree: every RM's skin at each level, its CPU time and size, one JSON line.
TREE_SCRIPT = """
import json, time
from ellimann_addon.core.mannequin.skin_record import SkinSettings
from ellimann_addon.core.skin.surface import build_skin
from ellimann_addon.core.synthesis.shipped import named_reference_set
figures = {}
for level, voxel in %r.items():
    rows = []
    for mannequin in named_reference_set(%r).mannequins[:%r]:
        start = time.process_time()
        skin = build_skin(mannequin, SkinSettings(voxel))
        rows.append((time.process_time() - start, len(skin.vertices)))
    figures[level] = rows
print(json.dumps(figures))
"""


def run_tree(tree, set_name, levels=LEVELS, count=None):
    script = TREE_SCRIPT % (levels, set_name, count)
    done = subprocess.run([sys.executable, "-c", script], cwd=tree, capture_output=True, text=True, check=False)
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    if not lines:
        print(f"  {tree}: no figures (exit {done.returncode}): {done.stderr.strip().splitlines()[-1:]}")
        return None
    return json.loads(lines[-1])


def exact_seconds(levels=LEVELS):
    import time

    from ellimann_addon.core.constants import TABLE_2_5
    from ellimann_addon.core.mannequin.skin_record import SkinSettings
    from ellimann_addon.core.skin.exact import exact_skin
    from ellimann_addon.core.synthesis.shipped import named_reference_set
    from ellimann_addon.core.synthesis.synthesize import synthesize

    mannequin, _, _ = synthesize(named_reference_set("female"), TABLE_2_5[0])
    rows = {}
    for level, voxel in levels.items():
        start = time.process_time()
        result = exact_skin(mannequin, SkinSettings(voxel))
        rows[level] = (time.process_time() - start, result.rounds, result.converged)
    return rows


def run(rounds=ROUNDS, before=BEFORE, set_name="female", quick=False):
    """``quick``: this tree only, one round, the preview level, one RM (checks that it runs)."""
    levels, count = ({"preview": LEVELS["preview"]}, 1) if quick else (LEVELS, None)
    rounds = 1 if quick else rounds
    figures = {"now": {level: [] for level in levels}, before: {level: [] for level in levels}}
    with tempfile.TemporaryDirectory(prefix="ellimann-bench-skin-") as scratch:
        trees = {"now": REPO}
        old = None if quick else worktree(before, pathlib.Path(scratch) / before)
        if old is not None:
            trees[before] = old
        elif not quick:
            print(f"  {before}: cannot check it out here (skipped)")
        try:
            for _ in range(rounds):
                for name, tree in trees.items():
                    result = run_tree(tree, set_name, levels, count) or {}
                    for level, rows in result.items():
                        figures[name][level] += rows
        finally:
            if old is not None:
                subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(old)], check=False)
    print(
        f"A skin of each of {count or 'the five'} {set_name} RMs, {rounds} round(s) per tree: median CPU s (vertices)"
    )
    for level, voxel in levels.items():
        now = [seconds for seconds, _ in figures["now"][level]]
        then = [seconds for seconds, _ in figures[before][level]]
        vertices = statistics.median(count for _, count in figures["now"][level]) if now else 0
        line = f"  {level:<8} {voxel:>4.0f} mm  now {statistics.median(now):6.2f} s ({vertices:,.0f} vertices)"
        if then:
            ratio = statistics.median(then) / statistics.median(now)
            line += f"   {before} {statistics.median(then):6.2f} s ({ratio:.2f}x now)"
        print(line)
    print("Exact mode on the skin, Table 2.5's first request (this tree): CPU s, rounds, met within 1 mm")
    for level, (seconds, rounds_made, converged) in exact_seconds(levels).items():
        print(f"  {level:<8} {seconds:6.2f} s  {rounds_made} round(s)  {'met' if converged else 'NOT met'}")
    return figures


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m bench.bench_skin", description=__doc__.split("\n")[0])
    parser.add_argument("--rounds", type=int, default=ROUNDS)
    parser.add_argument("--before", default=BEFORE, help=f"the older commit (default {BEFORE})")
    parser.add_argument("--set", default="female", help="the shipped reference set (default female)")
    args = parser.parse_args(argv)
    run(args.rounds, args.before, args.set)


if __name__ == "__main__":
    main()
