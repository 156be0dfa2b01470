"""The cloth's gap: how far a body's surface lies outside a mannequin's pieces.

A garment draped on the mannequin rests on its pieces; where the body's surface is outside every piece, the cloth
would sink that far into the body. For each vertex of the body mesh the one-sided distance to the mannequin
(core.drape.fit_metrics.BodyPieces: exact for ellipsoids, the hull meshes for cushions; 0 where the vertex is inside
a piece), weighted by the vertex's share of the surface area (core.fitting.body_mesh.vertex_areas): the share of the
surface outside the mannequin and the area-weighted median and 95th percentile of the distance over the whole
surface and over the part outside.

    python -m tools.figures.cloth_gap [--sets female,male,female-fine,male-fine] [--cushions]
"""

import numpy as np

from ellimann_addon.core.drape.fit_metrics import BodyPieces
from ellimann_addon.core.fitting.body_mesh import vertex_areas


def weighted_percentile(values, weights, q):
    """The smallest value below which ``q`` % of the weight lies (``values``, ``weights`` 1-d)."""
    order = np.argsort(values, kind="stable")
    cumulative = np.cumsum(weights[order])
    return float(values[order][np.searchsorted(cumulative, q / 100.0 * cumulative[-1])])


def surface_gap(mannequin, vertices, faces, cushions=False):
    """{"outside": share of the body's surface area outside every piece, "median", "p95": area-weighted percentiles
    (m) of the one-sided distance over the whole surface (0 inside), "outside_median", "outside_p95": the same over
    the surface outside}. ``vertices`` in the mannequin's frame (the body moved as its RM was, or stood with it)."""
    vertices = np.asarray(vertices, dtype=float)
    areas = vertex_areas(vertices, faces)
    distance, _ = BodyPieces(mannequin, cushions).signed_distance(vertices)
    gap = np.maximum(distance, 0.0)
    out = gap > 0.0
    return {
        "outside": float(areas[out].sum() / areas.sum()),
        "median": weighted_percentile(gap, areas, 50.0),
        "p95": weighted_percentile(gap, areas, 95.0),
        "outside_median": weighted_percentile(gap[out], areas[out], 50.0) if out.any() else 0.0,
        "outside_p95": weighted_percentile(gap[out], areas[out], 95.0) if out.any() else 0.0,
    }


def set_gaps(build_set, cushions=False):
    """{mannequin stem: surface_gap} of a shipped set's Base Mannequin and RMs, each stood in the body it was fitted
    to as tools/figures/overlap.py stands a twin (floors at z = 0, the volumes' centroids on one vertical line)."""
    from ellimann_addon.core.fitting.body_mesh import read_obj
    from ellimann_addon.core.geometry.volume import IOU_MARGIN, IOU_SPACING, BodyVolume
    from ellimann_addon.core.mannequin.model import Mannequin

    from ..shipped.bodies import RM_BODIES
    from .overlap import standing_in

    out = {}
    for stem, body_name in (("base_mannequin", build_set.reference_body), *((name, name) for name in RM_BODIES)):
        body = read_obj(build_set.refmodels / f"{body_name}.obj", up="z")
        grid = BodyVolume(body.vertices, body.faces).grid(IOU_SPACING, margin=IOU_MARGIN)
        mannequin = standing_in(grid, Mannequin.load(build_set.out / f"{stem}.json"))
        out[stem] = surface_gap(mannequin, body.vertices, body.faces, cushions)
    return out


def main(argv=None):
    import argparse

    from ..shipped.reference_sets import BUILD_SETS

    parser = argparse.ArgumentParser(prog="python -m tools.figures.cloth_gap", description=__doc__.split("\n")[0])
    parser.add_argument("--sets", default=",".join(BUILD_SETS), help=f"comma-separated, of {', '.join(BUILD_SETS)}")
    parser.add_argument("--cushions", action="store_true", help="the cushion mannequins (slower)")
    args = parser.parse_args(argv)
    print("| set | mannequin | surface outside | median (mm) | p95 (mm) | outside: median | p95 |")
    print("|---|---|---|---|---|---|---|")
    for name in args.sets.split(","):
        for stem, gap in set_gaps(BUILD_SETS[name], args.cushions).items():
            print(
                f"| {name} | {stem} | {gap['outside']:.0%} | {gap['median'] * 1e3:.1f} | {gap['p95'] * 1e3:.1f} | "
                f"{gap['outside_median'] * 1e3:.1f} | {gap['outside_p95'] * 1e3:.1f} |"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
