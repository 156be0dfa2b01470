"""Run every benchmark: ``python -m bench [-v] [--quick] [NAME…]`` (or ``make bench``).

What Blender prints is captured, so only the benchmarks' own lines show; ``-v`` / ``--verbose``
shows Blender's output too (on stderr). ``--quick``: each benchmark's quick mode (a few requests, one repetition,
no older commit checked out): it checks that every benchmark still runs (the tests run each one's quick mode:
tests/core/test_bench_quick.py, tests/blender/test_bench_quick_blender.py); its figures mean nothing.
"""

import importlib
import sys

BENCHES = (
    "bench_core",
    "bench_synthesis",
    "bench_live",
    "bench_live_skin",
    "bench_exact_population",
    "bench_male",
    "bench_pose",
    "bench_skin",
    "bench_skin_posing",
    "bench_skin_batch",
    "bench_drape",
    "bench_walk_drape",
    "bench_references",
    "bench_scan",
    "bench_scan_held_out",
    "bench_extra",
    "bench_skin_exact",
    "bench_bvh",
    "bench_batch",
    "bench_fine",
    "bench_body_skin",
    "bench_body_space",
)

# The benchmarks that need the bpy module (Blender's cloth, the panel, its importer): their quick modes run in
# tests/blender/test_bench_quick_blender.py, the others' in tests/core/test_bench_quick.py.
NEEDS_BLENDER = (
    "bench_synthesis",
    "bench_live",
    "bench_live_skin",
    "bench_drape",
    "bench_walk_drape",
    "bench_bvh",
    "bench_fine",
)


def main(names=None, verbose=False, quick=False):
    from ellimann_addon.blender.services.chatter import program

    with program(show=verbose):
        for name in names or BENCHES:
            print(f"== {name}{' (quick)' if quick else ''} ==")
            importlib.import_module(f"bench.{name}").run(quick=quick)
            print()


if __name__ == "__main__":
    arguments = sys.argv[1:]
    flags = {"-v", "--verbose", "--quick"}
    main(
        [a for a in arguments if a not in flags],
        verbose=bool({"-v", "--verbose"} & set(arguments)),
        quick="--quick" in arguments,
    )
