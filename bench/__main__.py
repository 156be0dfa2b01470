"""Run every benchmark: ``python -m bench [-v] [NAME…]`` (or ``make bench``).

What Blender prints is captured, so only the benchmarks' own lines show; ``-v`` / ``--verbose``
shows Blender's output too (on stderr).
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
)


def main(names=None, verbose=False):
    from ellimann_addon.blender.services.chatter import program

    with program(show=verbose):
        for name in names or BENCHES:
            print(f"== {name} ==")
            importlib.import_module(f"bench.{name}").run()
            print()


if __name__ == "__main__":
    arguments = sys.argv[1:]
    flags = {"-v", "--verbose"}
    main([a for a in arguments if a not in flags], verbose=bool(flags & set(arguments)))
