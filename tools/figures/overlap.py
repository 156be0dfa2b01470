"""How well a mannequin synthesized from a body's measurements overlaps that body: voxel IoU.

    .venv/bin/python -m tools.figures.overlap [--set female|male|both] [--spacing M] [--skin-voxel MM]

For each of a set's six bodies (tools/shipped/reference_sets.py): measure the body as its README does (at the
set's section heights), synthesize a mannequin from those five numbers with the set's shipped Reference
Mannequins (exact mode), stand it where the body stands (the floors at z = 0 and the volumes' centroids
on one vertical line, since a synthesized mannequin is registered on its own landmark) and compare the
voxels they fill: core.geometry.volume.voxel_iou, of the ellipsoids and of the cushions (the convex pieces),
and core.geometry.volume.mesh_voxel_iou of the skin (core.skin) over those pieces and of the exact skin (the
pieces refined until their skin, not the pieces, measures the body's five: core.skin.exact), at --skin-voxel.
"""

import argparse
import sys

import numpy as np

from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry import volume
from ellimann_addon.core.mannequin.skin_record import SkinSettings
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.settings import LEVELS
from ellimann_addon.core.skin.exact import exact_skin
from ellimann_addon.core.skin.surface import build_skin
from ellimann_addon.core.synthesis.reference_set import load_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize_batch

from ..shipped.bodies import RM_BODIES, body_measurements, load_labels
from ..shipped.reference_sets import BUILD_SETS, TRACING_FOLDER


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


COLUMNS = ("ellipsoids", "cushions", "skin", "exact skin")


def set_overlaps(build_set, spacing=volume.IOU_SPACING, skin_voxel_mm=None, bodies=None):
    """{body: {column: IoU}} of the set's six bodies (or ``bodies``) against mannequins synthesized from their
    measurements with the set's shipped Reference Mannequins: their ellipsoids, their cushions and, with
    ``skin_voxel_mm``, the skin over those pieces and the exact skin (COLUMNS)."""
    labels = load_labels(TRACING_FOLDER)
    reference = load_reference_set(build_set.out)
    out = {}
    for name in bodies or (build_set.reference_body, *RM_BODIES):
        body = read_obj(build_set.refmodels / f"{name}.obj", up="z")
        measured = body_measurements(body, labels, build_set.fractions)
        mannequin = synthesize_batch(reference, [[measured[key] for key in MEASUREMENTS]]).mannequin(0)
        grid = volume.BodyVolume(body.vertices, body.faces).grid(spacing, margin=volume.IOU_MARGIN)
        moved = standing_in(grid, mannequin)
        out[name] = {
            kind: volume.voxel_iou(moved, grid=grid, cushions=kind == "cushions") for kind in ("ellipsoids", "cushions")
        }
        if skin_voxel_mm is not None:
            settings = SkinSettings(skin_voxel_mm)
            for kind, skin in (
                ("skin", build_skin(mannequin, settings)),
                ("exact skin", exact_skin(mannequin, settings, measured).skin),
            ):
                # stood where its own pieces stand best (a skin over pieces is centred as they are)
                stood = skin.following(standing_in(grid, skin.mannequin))
                out[name][kind] = volume.mesh_voxel_iou(stood.vertices, stood.faces, grid)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.figures.overlap", description=__doc__.split("\n")[0])
    parser.add_argument("--set", choices=[*sorted(BUILD_SETS), "both"], default="both")
    parser.add_argument("--spacing", type=float, default=volume.IOU_SPACING, help="grid spacing (m)")
    parser.add_argument(
        "--skin-voxel",
        type=float,
        default=LEVELS["final"],
        metavar="MM",
        help="the skins' voxel in mm (default: the final level's); 0: no skins",
    )
    args = parser.parse_args(argv)
    names = sorted(BUILD_SETS) if args.set == "both" else [args.set]
    columns = COLUMNS if args.skin_voxel else COLUMNS[:2]
    print("| set | body | " + " | ".join(f"IoU, {column}" for column in columns) + " |")
    print("|---|---|" + "---|" * len(columns))
    for name in names:
        figures = set_overlaps(BUILD_SETS[name], args.spacing, args.skin_voxel or None)
        for body, row in figures.items():
            print(f"| {name} | {body} | " + " | ".join(f"{row[column]:.3f}" for column in columns) + " |")
        mean = [np.mean([row[column] for row in figures.values()]) for column in columns]
        print(f"| {name} | mean of {len(figures)} | " + " | ".join(f"{value:.3f}" for value in mean) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
