"""Scan to mannequin on bodies the reference set has not seen: each of a set's six bodies held out in turn, its
twin synthesized (exact mode) from the other five bodies' Reference Mannequins with the five measurements its mesh
gives and with all eleven, and the IoU of each twin with the body (bench_scan's overlap: 5 mm voxels, the twin
stood in the body); with ``--gap``, also how far the body's surface lies outside the twin from its five (the cloth's
gap, tools/figures/cloth_gap.py).

bench_scan's bodies are, but for the neutral one, the bodies of the shipped RMs, whose five-measurement twin
is nearly their own RM: this is the fair test of what the extra measurements add. The six RMs are built once
by the product's builder (tools.figures.held_out.six_rms: an RM depends only on its own body), a few minutes per set.

    python -m bench bench_scan_held_out                        # the female set (the paper's 40)
    python -m bench.bench_scan_held_out --sets female,female-fine,male,male-fine --gap
"""

import argparse
import statistics

import numpy as np

from bench.bench_scan import SPACING, twin_overlaps
from ellimann_addon.core.geometry.volume import IOU_MARGIN, BodyVolume
from ellimann_addon.core.measure.body import measure_body_mesh
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.shipped import named_reference_set
from tools.figures.cloth_gap import surface_gap
from tools.figures.held_out import six_rms, subset_set
from tools.figures.overlap import standing_in
from tools.shipped.bodies import read_bodies
from tools.shipped.build_reference import DEFAULT_REFMODELS
from tools.shipped.reference_sets import BUILD_SETS, FEMALE


def held_out(build_set=FEMALE, workers=2, gap=False, quick=False):
    """Rows {held-out body: (IoU five, IoU all, extra measurements missed, cloth gap of the five's twin or None)}.
    ``quick``: the shipped female RMs instead of six built (minutes), the neutral body (which none of them is) held
    out against the five (checks that the rest runs)."""
    if quick:
        rms, targets, bodies = shipped_five(DEFAULT_REFMODELS)
    elif build_set is FEMALE:
        rms, targets, _, bodies = six_rms(DEFAULT_REFMODELS, workers)
    else:
        rms, targets, _, bodies = six_rms(build_set.refmodels, workers, build_set)
    rows = {}
    for held, body in bodies.items():
        found = measure_body_mesh(body.vertices, body.faces, build_set.fractions).values
        others = subset_set(rms, targets, [name for name in rms if name != held])
        five_iou, all_iou, missed, twin = twin_overlaps(others, body, found, with_twin=True)
        stats = None
        if gap:
            grid = BodyVolume(body.vertices, body.faces).grid(SPACING, margin=IOU_MARGIN)
            stats = surface_gap(standing_in(grid, twin), body.vertices, body.faces)
        rows[held] = (five_iou, all_iou, missed, stats)
    return rows


def shipped_five(refmodels):
    """(the shipped female RMs {stem: RM}, their targets {stem: {He..Hi}}, {the neutral body: BodyMesh})."""
    reference = named_reference_set("female")
    rms = dict(zip(reference.names, reference.mannequins))
    targets = {name: dict(zip(MEASUREMENTS, row)) for name, row in zip(reference.names, reference.measurements)}
    return rms, targets, read_bodies(refmodels, ["reference_female"])


def run(sets=("female",), workers=2, gap=False, quick=False):
    """``quick``: see :func:`held_out`, with the cloth gap (checks that it runs)."""
    for name in sets:
        rows = held_out(BUILD_SETS[name], workers, gap or quick, quick)
        print(f"{name}: {'held-out body':<17} {'IoU five':>9} {'IoU all':>8} {'gain':>6}  extra measurements missed")
        for held, (five_iou, all_iou, missed, stats) in rows.items():
            line = (
                f"{name}: {held:<17} {five_iou:9.3f} {all_iou:8.3f} {all_iou - five_iou:+6.3f}  "
                f"{', '.join(missed) or 'none'}"
            )
            if stats is not None:
                line += (
                    f"; cloth gap {stats['outside']:.0%} of the surface outside, "
                    f"median {stats['median'] * 1e3:.1f} mm, p95 {stats['p95'] * 1e3:.1f} mm"
                )
            print(line)
        five = [row[0] for row in rows.values()]
        gains = [row[1] - row[0] for row in rows.values()]
        print(
            f"{name}: mean IoU five {statistics.mean(five):.3f}; mean gain with all measurements, held out: "
            f"{statistics.mean(gains):+.3f} (min {min(gains):+.3f}, max {max(gains):+.3f}; "
            f"{int(np.sum(np.array(gains) > 0))} of {len(gains)} gain)"
        )
        if gap or quick:
            for key in ("median", "p95"):
                values = [row[3][key] * 1e3 for row in rows.values()]
                print(f"{name}: cloth gap {key} over the six: mean {statistics.mean(values):.1f} mm")


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m bench.bench_scan_held_out", description=__doc__.split("\n")[0])
    parser.add_argument("--sets", default="female", help=f"comma-separated, of {', '.join(BUILD_SETS)}")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--gap", action="store_true", help="also the cloth's gap of each twin from five")
    args = parser.parse_args(argv)
    run(args.sets.split(","), args.workers, args.gap)


if __name__ == "__main__":
    main()
