"""How many more convex pieces would bring a shipped Reference Mannequin's coverage of its body to a target: a
greedy bound with balls (docs/topology_fine_tried.md, "Filling what is left").

    .venv/bin/python -m tools.figures.fill_bound [--set female-fine] [--target 0.94] [--outset MM] [--most N]

Each RM stands in its body as tools/figures/overlap.py stands it (5 mm grid). Balls are added one at a time, each the
one that adds the most body cells no piece fills less the outside cells it adds (a cell outside costs what a cell inside
is worth, as the fine topology's fit weighs them). A ball is centred inside the body and reaches ``outset`` past the
nearest point of the body's surface, and it crosses no section band (the set's section heights, ``clearance`` of
the height either side): a part that crosses a section follows its measurement. Placed freely on each body, a
ball is about the most a new piece of its size can add; a topology's part is placed by a box drawn once on the
reference body and fitted inside the walls, and adds less.
"""

import argparse
import heapq
import sys

import numpy as np
from scipy.spatial import cKDTree

from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry.volume import IOU_MARGIN, IOU_SPACING, occupancy
from ellimann_addon.core.mannequin.model import Mannequin

from ..shipped.bodies import RM_BODIES
from ..shipped.coverage import BodyVolume
from ..shipped.reference_sets import BUILD_SETS
from .overlap import standing_in

REACH = 0.04  # m: the deepest a ball's centre lies (radius up to REACH + outset)
CLEARANCE = 0.0125  # of the height, either side of a section: the fine topology's


def fill_curve(body, grid, mannequin, outset=0.002, clearance=CLEARANCE, reach=REACH, most=120, target=None):
    """[(coverage, excess)] of ``mannequin`` (standing in ``body``, a tools.shipped.coverage.BodyVolume, on its
    ``grid``) with 0, 1, 2, ... greedy balls added, up to ``most`` or until coverage reaches ``target``; and the balls
    [(centre, radius)]. A ball's centre lies at most ``reach`` deep."""
    inside, filled = grid.inside.ravel(), occupancy(grid, mannequin).ravel()
    points = grid.origin + grid.spacing * np.argwhere(np.ones(grid.inside.shape, dtype=bool))
    body_cells = np.flatnonzero(inside)
    depth = np.concatenate([body.distance(points[chunk])[0] for chunk in np.array_split(body_cells, 32)])
    # the cells a ball can reach: inside, or outside within its reach of the surface
    outside = np.flatnonzero(~inside)
    near = cKDTree(body.vertices).query(points[outside], distance_upper_bound=reach + outset)[0] < np.inf
    reachable = np.concatenate([body_cells, outside[near]])
    empty = np.zeros(len(points), dtype=bool)
    empty[reachable] = ~filled[reachable]
    worth = np.where(inside, 1, -1)  # what each empty cell adds to a ball's value

    z = body.vertices[:, 2]
    height = z.max() - z.min()
    sections = z.min() + height * np.array(list(mannequin.section_fractions.values()))
    shallow = depth <= reach
    centres, radii = body_cells[shallow], depth[shallow] + outset
    lo, hi = points[centres, 2] - radii, points[centres, 2] + radii
    band = clearance * height
    clear = ~np.any((lo[:, None] < sections + band) & (hi[:, None] > sections - band), axis=1)
    centres, radii = centres[clear], radii[clear]

    tree = cKDTree(points[reachable])

    def value(k):
        cells = reachable[tree.query_ball_point(points[centres[k]], radii[k])]
        cells = cells[empty[cells]]
        return int(worth[cells].sum()), cells

    covered, spilled = int(np.count_nonzero(filled & inside)), int(np.count_nonzero(filled & ~inside))
    curve = [(covered / len(body_cells), spilled / (covered + spilled))]
    heap = [(-v, k) for k in range(len(centres)) if (v := value(k)[0]) > 0]
    heapq.heapify(heap)
    balls = []
    while heap and len(balls) < most and (target is None or curve[-1][0] < target):
        _, k = heapq.heappop(heap)
        # re-valued when it comes up: a value falls by the cells inside that other balls took (and rises a little by
        # the outside they already paid for, which the order does not chase)
        gain, cells = value(k)
        if gain <= 0:
            continue
        if heap and gain < -heap[0][0]:
            heapq.heappush(heap, (-gain, k))
            continue
        empty[cells] = False
        covered += int(np.count_nonzero(inside[cells]))
        spilled += int(np.count_nonzero(~inside[cells]))
        curve.append((covered / len(body_cells), spilled / (covered + spilled)))
        balls.append((points[centres[k]], float(radii[k])))
    return curve, balls


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.figures.fill_bound", description=__doc__.split("\n")[0])
    parser.add_argument("--set", choices=sorted(BUILD_SETS), default="female-fine")
    parser.add_argument("--target", type=float, default=0.94, help="the coverage to reach (share)")
    parser.add_argument("--outset", type=float, default=2.0, help="mm a ball reaches past the body's surface")
    parser.add_argument("--most", type=int, default=120, help="the most balls added to one RM")
    args = parser.parse_args(argv)
    build_set = BUILD_SETS[args.set]
    print("| RM | coverage | excess | balls to the target | then coverage | excess |")
    print("|---|---|---|---|---|---|")
    for name in RM_BODIES:
        mannequin = Mannequin.load(build_set.out / f"{name}.json")
        mesh = read_obj(build_set.refmodels / f"{name}.obj", up="z")
        body = BodyVolume(mesh.vertices, mesh.faces)
        grid = body.grid(IOU_SPACING, margin=IOU_MARGIN)  # tools/figures/overlap.py's
        curve, balls = fill_curve(
            body, grid, standing_in(grid, mannequin), args.outset / 1000, most=args.most, target=args.target
        )
        reached = curve[-1][0] >= args.target
        print(
            f"| {name} | {curve[0][0]:.2%} | {curve[0][1]:.2%} | {len(balls) if reached else f'over {args.most}'} | "
            f"{curve[-1][0]:.2%} | {curve[-1][1]:.2%} |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
