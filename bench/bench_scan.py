"""Scan to mannequin: the time to measure a body mesh, and how much the extra measurements make a synthesized
twin overlap its body (core.geometry.volume.voxel_iou of its ellipsoids, the twin stood as tools/figures/overlap.py
stands it), on the six female reference bodies of ../shared/refmodels.

Per body: measure the mesh (core.measure.body, no labels), synthesize in exact mode with the five it found, with
the five and each extra measurement alone, and with all it found (core.synthesis.extra_refine), and count the IoU of
each
twin with the body. Also: the time to
measure one 27k-triangle body (the median of three runs) and what the five's measurement differs from the
README's table by.
"""

import statistics
import time

from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry.volume import IOU_MARGIN, BodyVolume, voxel_iou
from ellimann_addon.core.measure.body import measure_body_mesh
from ellimann_addon.core.measure.extra import split_measurements
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.shipped import named_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize_extra
from tools.figures.overlap import standing_in
from tools.shipped.bodies import body_measurements, load_labels
from tools.shipped.reference_sets import TRACING_FOLDER

BODIES = ("reference_female", "small_slim", "tall_slim", "small_chubby", "tall_chubby", "average")
SPACING = 0.005


def overlap(mannequin, body):
    """IoU of the mannequin's ellipsoids and the body, the mannequin stood where the body stands."""
    grid = BodyVolume(body.vertices, body.faces).grid(SPACING, margin=IOU_MARGIN)
    return voxel_iou(standing_in(grid, mannequin), grid=grid, cushions=False)


def twin_overlaps(reference, body, found, with_twin=False):
    """(IoU of the twin from the five, IoU of the twin from all of ``found``, the extra measurements missed; with
    ``with_twin``, also the twin from the five)."""
    five, extra = split_measurements(found)
    iou, missed, twins = [], [], []
    for given in ({}, extra):
        result = synthesize_extra(reference, five, given)
        missed += [miss.key for miss in result.missed]
        iou.append(overlap(result.mannequin, body))
        twins.append(result.mannequin)
    return (iou[0], iou[1], missed, twins[0]) if with_twin else (iou[0], iou[1], missed)


def run(quick=False):
    """``quick``: one body, measured once, one extra measurement alone (checks that it runs)."""
    reference = named_reference_set("female")
    labels = load_labels(TRACING_FOLDER)
    print(f"{'body':<17} {'measure s':>9} {'max |five - README| cm':>22} {'IoU five':>9} {'IoU all':>8} {'gain':>6}")
    gains = []
    for name in BODIES[: 1 if quick else None]:
        body = read_obj(TRACING_FOLDER / f"{name}.obj", up="z")
        times = []
        for _ in range(1 if quick else 3):
            start = time.perf_counter()
            result = measure_body_mesh(body.vertices, body.faces)
            times.append(time.perf_counter() - start)
        readme = body_measurements(body, labels)
        worst = max(abs(result.values[key] - readme[key]) for key in MEASUREMENTS if key in result.values)
        five, extra = split_measurements(result.values)
        five_iou, all_iou, missed = twin_overlaps(reference, body, result.values)
        gains.append(all_iou - five_iou)
        alone = []
        for key, value in list(extra.items())[: 1 if quick else None]:
            mannequin = synthesize_extra(reference, five, {key: value}).mannequin
            alone.append(f"{key} {overlap(mannequin, body) - five_iou:+.3f}")
        print(
            f"{name:<17} {statistics.median(times):9.2f} {worst:22.3f} {five_iou:9.3f} {all_iou:8.3f} "
            f"{all_iou - five_iou:+6.3f}  ({len(body.faces)} triangles; not measured: {result.missing or 'none'}; "
            f"missed by the twin: {missed or 'none'})"
        )
        print(f"{'':<17} IoU change with one extra measurement alone: {', '.join(alone)}")
    print(f"mean IoU gain with all measurements: {statistics.mean(gains):+.3f}")


if __name__ == "__main__":
    run()
