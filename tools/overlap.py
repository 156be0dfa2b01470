"""How well a mannequin synthesized from a body's measurements overlaps that body: voxel IoU.

    .venv/bin/python -m tools.overlap [--set female|male|both] [--spacing M]

For each of a set's six bodies (tools/reference_sets.py): measure the body as its README does (at the
set's section heights), synthesize a mannequin from those five numbers with the set's shipped Reference
Mannequins (exact mode), stand it where the body stands (the floors at z = 0 and the volumes' centroids
on one vertical line, since a synthesized mannequin is registered on its own landmark) and count, on a
regular grid, the cells inside the body, inside the mannequin's pieces and inside both:
IoU = |body ∩ mannequin| / |body ∪ mannequin|. Body volumes as core/volume.py counts them.
"""

import argparse
import sys

import numpy as np

from ellimann_addon.core import volume
from ellimann_addon.core.body_mesh import read_obj
from ellimann_addon.core.reference_set import load_reference_set
from ellimann_addon.core.synthesis import synthesize_batch

from .bodies import RM_BODIES, body_measurements, load_labels
from .reference_sets import BUILD_SETS, TRACING_FOLDER


def voxel_iou(mannequin, vertices, faces, spacing=volume.GRID_SPACING, cushions=False):
    """(IoU, coverage, excess) of ``mannequin`` and the closed body mesh on a grid of ``spacing`` (m), after
    moving the mannequin so that its volume's centroid lies above the body's (x, y only)."""
    body = volume.BodyVolume(vertices, faces)
    grid = body.grid(spacing)
    cells = grid.origin + spacing * np.argwhere(grid.inside)
    # first onto the body's line by the pieces' volume-weighted centres (wherever the mannequin stands),
    # then by the centroid of the cells it fills, counting overlaps once
    weights = np.prod(mannequin.semi_axes, axis=1)
    shift = np.zeros(3)
    shift[:2] = cells[:, :2].mean(axis=0) - weights @ mannequin.center[:, :2] / weights.sum()
    occupied = volume.occupancy(grid, mannequin.copy(center=mannequin.center + shift), cushions)
    own = grid.origin + spacing * np.argwhere(occupied)
    shift[:2] += cells[:, :2].mean(axis=0) - own[:, :2].mean(axis=0)
    occupied = volume.occupancy(grid, mannequin.copy(center=mannequin.center + shift), cushions)
    both = np.count_nonzero(occupied & grid.inside)
    union = np.count_nonzero(occupied | grid.inside)
    return both / union, both / np.count_nonzero(grid.inside), 1.0 - both / max(np.count_nonzero(occupied), 1)


def set_overlaps(build_set, spacing=volume.GRID_SPACING):
    """{body: (IoU, coverage, excess)} of the set's six bodies against mannequins synthesized from their
    measurements with the set's shipped Reference Mannequins."""
    labels = load_labels(TRACING_FOLDER)
    reference = load_reference_set(build_set.out)
    out = {}
    for name in (build_set.reference_body, *RM_BODIES):
        body = read_obj(build_set.refmodels / f"{name}.obj")
        measured = body_measurements(body, labels, build_set.fractions)
        request = [[measured[key] for key in ("He", "Sh", "Br", "Wa", "Hi")]]
        mannequin = synthesize_batch(reference, request).mannequin(0)
        out[name] = voxel_iou(mannequin, body.vertices, body.faces, spacing)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.overlap", description=__doc__.split("\n")[0])
    parser.add_argument("--set", choices=[*sorted(BUILD_SETS), "both"], default="both")
    parser.add_argument("--spacing", type=float, default=volume.GRID_SPACING, help="grid spacing (m)")
    args = parser.parse_args(argv)
    names = sorted(BUILD_SETS) if args.set == "both" else [args.set]
    print("| set | body | IoU | coverage | excess |")
    print("|---|---|---|---|---|")
    for name in names:
        figures = set_overlaps(BUILD_SETS[name], args.spacing)
        for body, (iou, covered, excess) in figures.items():
            print(f"| {name} | {body} | {iou:.3f} | {covered:.1%} | {excess:.1%} |")
        mean = np.mean([f[0] for f in figures.values()])
        print(f"| {name} | mean of {len(figures)} | {mean:.3f} | | |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
