"""Run every benchmark: ``python -m bench`` (or ``make bench``)."""

import importlib
import sys

BENCHES = ("bench_core", "bench_synthesis", "bench_drape")


def main(names=None):
    for name in names or BENCHES:
        print(f"== {name} ==")
        importlib.import_module(f"bench.{name}").run()
        print()


if __name__ == "__main__":
    main(sys.argv[1:])
