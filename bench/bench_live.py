"""The Synthesize panel's Live step, headless, now against older commits in the same run (issue 26: "live first").

Each commit is checked out in a temporary git worktree; every tree (those commits', and this one) runs
``bench/live_step.py`` in a process of its own (two trees cannot share one bpy process: the same add-on names),
in ROUNDS rounds, the trees in turn each round, so that the machine's load falls on all of them alike. Each run
synthesizes at He 159 in exact mode, turns Live on and drags He over 15 steps (150-170 cm), with ellipsoids,
with cushions (and the armature Synthesize builds where the reference set has joints), and with cushions but the
armature removed; then it times one exact request through the core (``synthesize``) and as the live step asks
for it. Printed: the median ms of each case per tree over all rounds, wall and CPU (the process's own, less at
the mercy of other work on a shared machine), and each older tree's median over this tree's. Each tree uses its
own shipped Reference Mannequins (eb01e27's had no joints, so no armature).

``python -m bench.bench_live [COMMIT ...]`` (default: eb01e27, from before the posing work and the extra
measurements: the commit issue 26 measured the step against).
"""

import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile

REPO = pathlib.Path(__file__).resolve().parents[1]
BASELINES = ("eb01e27",)
ROUNDS = 3
CASES = ("ellipsoids", "cushions", "cushions, no rig", "single request", "panel request")
LABELS = {
    "ellipsoids": "live step, ellipsoids",
    "cushions": "live step, cushions (+ rig where built)",
    "cushions, no rig": "live step, cushions, rig removed",
    "single request": "one exact request (core synthesize)",
    "panel request": "one exact request (the live step's)",
}


def run_tree(tree, quick=False):
    """The cases' ms of one run of ``tree`` (live_step.py in a fresh process; ``quick``: three steps), or None if it
    failed."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    done = subprocess.run(
        [sys.executable, str(REPO / "bench" / "live_step.py"), *(["--quick"] if quick else [])],
        cwd=str(tree),
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    if not lines:
        print(f"  {tree}: no figures (exit {done.returncode}): {done.stderr.strip().splitlines()[-1:]}")
        return None
    return json.loads(lines[-1])


def worktree(commit, folder):
    """A detached worktree of ``commit`` in ``folder`` (None if git cannot make it)."""
    done = subprocess.run(
        ["git", "-C", str(REPO), "worktree", "add", "--detach", str(folder), commit], capture_output=True, text=True
    )
    return folder if done.returncode == 0 else None


def run(commits=BASELINES, rounds=ROUNDS, quick=False):
    """``quick``: this tree only, one round of three steps (checks that it runs)."""
    if quick:
        commits, rounds = (), 1
    with tempfile.TemporaryDirectory(prefix="ellimann-bench-live-") as scratch:
        trees = {}
        for commit in commits:
            tree = worktree(commit, pathlib.Path(scratch) / commit)
            if tree is None:
                print(f"  {commit}: cannot check it out here (skipped)")
            else:
                trees[commit] = tree
        trees["now"] = REPO
        try:
            figures = {name: {case: [] for case in CASES} for name in trees}
            rigged = {}
            for _ in range(rounds):
                for name, tree in trees.items():
                    result = run_tree(tree, quick)
                    for case in CASES if result else ():
                        figures[name][case] += result.get(case) or []
                    rigged[name] = bool(result and result.get("rig"))
        finally:
            for name, tree in trees.items():
                if name != "now":
                    subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(tree)], check=False)
    report(figures, rigged, rounds)
    return figures


def report(figures, rigged, rounds):
    names = list(figures)
    print(
        f"Live step, He steps x {rounds} rounds per tree; armature built: "
        + ", ".join(f"{name} {'yes' if rigged.get(name) else 'no'}" for name in names)
    )
    for column, title in ((0, "wall"), (1, "CPU (this process)")):
        print(f"  median {title} ms (in brackets: that tree's median / now's)")
        print(f"  {'':42}" + "".join(f"{name:>22}" for name in names))
        for case in CASES:
            now = [pair[column] for pair in figures["now"][case]]
            cells = []
            for name in names:
                values = [pair[column] for pair in figures[name][case]]
                if not values:
                    cells.append(f"{'-':>22}")
                    continue
                median = statistics.median(values)
                ratio = f" ({median / statistics.median(now):5.2f}x)" if now and name != "now" else ""
                cells.append(f"{median:>10.2f}{ratio:>12}")
            print(f"  {LABELS[case]:<42}" + "".join(cells))


if __name__ == "__main__":
    run(tuple(sys.argv[1:]) or BASELINES)
