"""Scan to mannequin on bodies the reference set has not seen: each of the six female bodies held out in turn,
its twin synthesized (exact mode) from the other five bodies' Reference Mannequins with the five measurements
its mesh gives and with all eleven, and the IoU of each twin with the body (bench_scan's overlap: 5 mm
voxels, the twin stood in the body).

bench_scan's bodies are, but for reference_female, the bodies of the shipped RMs, whose five-measurement twin
is nearly their own RM: this is the fair test of what the extra measurements add. The six RMs are built once
by the product's builder (tools.held_out.six_rms: an RM depends only on its own body), a few minutes.
"""

import statistics

import numpy as np

from bench.bench_scan import twin_overlaps
from ellimann_addon.core.measure.body import measure_body_mesh
from tools.build_reference import DEFAULT_REFMODELS
from tools.held_out import six_rms, subset_set


def run(workers=2):
    rms, targets, _, bodies = six_rms(DEFAULT_REFMODELS, workers)
    print(f"{'held-out body':<17} {'IoU five':>9} {'IoU all':>8} {'gain':>6}  extra measurements missed")
    gains = []
    for held, body in bodies.items():
        found = measure_body_mesh(body.vertices, body.faces).values
        others = subset_set(rms, targets, [name for name in rms if name != held])
        five_iou, all_iou, missed = twin_overlaps(others, body, found)
        gains.append(all_iou - five_iou)
        print(f"{held:<17} {five_iou:9.3f} {all_iou:8.3f} {all_iou - five_iou:+6.3f}  {', '.join(missed) or 'none'}")
    print(
        f"mean IoU gain with all measurements, held out: {statistics.mean(gains):+.3f} "
        f"(min {min(gains):+.3f}, max {max(gains):+.3f}; {int(np.sum(np.array(gains) > 0))} of {len(gains)} gain)"
    )


if __name__ == "__main__":
    run()
