"""How well a mannequin synthesized from a body's measurements overlaps that body: voxel IoU.

    .venv/bin/python -m tools.overlap [--set female|male|both] [--spacing M]

For each of a set's six bodies (tools/reference_sets.py): measure the body as its README does (at the
set's section heights), synthesize a mannequin from those five numbers with the set's shipped Reference
Mannequins (exact mode), stand it where the body stands (the floors at z = 0 and the volumes' centroids
on one vertical line, since a synthesized mannequin is registered on its own landmark) and compare the
voxels they fill: core.geometry.volume.voxel_iou, of the ellipsoids and of the cushions (the convex pieces).
"""

import argparse
import sys

import numpy as np

from ellimann_addon.core.constants import MEASUREMENTS
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry import volume
from ellimann_addon.core.synthesis.reference_set import load_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize_batch

from .bodies import RM_BODIES, body_measurements, load_labels
from .reference_sets import BUILD_SETS, TRACING_FOLDER


def standing_in(grid, mannequin):
    """``mannequin`` moved (x, y only) so that the centroid of the cells it fills lies above the body's: first
    by its pieces' volume-weighted centres (wherever it stands), then by the cells it fills, overlaps once."""
    cells = grid.origin + grid.spacing * np.argwhere(grid.inside)
    weights = np.prod(mannequin.semi_axes, axis=1)
    shift = np.zeros(3)
    shift[:2] = cells[:, :2].mean(axis=0) - weights @ mannequin.center[:, :2] / weights.sum()
    moved = mannequin.copy(center=mannequin.center + shift)
    own = grid.origin + grid.spacing * np.argwhere(volume.occupancy(grid, moved))
    shift[:2] = cells[:, :2].mean(axis=0) - own[:, :2].mean(axis=0)
    return moved.copy(center=moved.center + shift)


def set_overlaps(build_set, spacing=volume.IOU_SPACING):
    """{body: (IoU of the ellipsoids, IoU of the cushions)} of the set's six bodies against mannequins
    synthesized from their measurements with the set's shipped Reference Mannequins."""
    labels = load_labels(TRACING_FOLDER)
    reference = load_reference_set(build_set.out)
    out = {}
    for name in (build_set.reference_body, *RM_BODIES):
        body = read_obj(build_set.refmodels / f"{name}.obj", up="z")
        measured = body_measurements(body, labels, build_set.fractions)
        mannequin = synthesize_batch(reference, [[measured[key] for key in MEASUREMENTS]]).mannequin(0)
        grid = volume.BodyVolume(body.vertices, body.faces).grid(spacing, margin=volume.IOU_MARGIN)
        mannequin = standing_in(grid, mannequin)
        out[name] = tuple(volume.voxel_iou(mannequin, grid=grid, cushions=cushions) for cushions in (False, True))
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.overlap", description=__doc__.split("\n")[0])
    parser.add_argument("--set", choices=[*sorted(BUILD_SETS), "both"], default="both")
    parser.add_argument("--spacing", type=float, default=volume.IOU_SPACING, help="grid spacing (m)")
    args = parser.parse_args(argv)
    names = sorted(BUILD_SETS) if args.set == "both" else [args.set]
    print("| set | body | IoU, ellipsoids | IoU, cushions |")
    print("|---|---|---|---|")
    for name in names:
        figures = set_overlaps(BUILD_SETS[name], args.spacing)
        for body, (ellipsoids, cushions) in figures.items():
            print(f"| {name} | {body} | {ellipsoids:.3f} | {cushions:.3f} |")
        mean = np.mean(list(figures.values()), axis=0)
        print(f"| {name} | mean of {len(figures)} | {mean[0]:.3f} | {mean[1]:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
