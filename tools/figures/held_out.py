"""What more Reference Mannequins buy: the overlap of a synthesized mannequin with a body not in its set.

    .venv/bin/python -m tools.figures.held_out [--refmodels DIR] [--workers N] [--out FILE.md]

The six female bodies of ../shared/refmodels are built into RMs once, by the product's builder (an RM depends
only on its own body: fitted, refined and cleaned alone; only its axis labels follow the set's reference RM,
here the Average), with each body's own joints (skeleton.json) as the shipped RMs have them. Then, leaving
each body out in turn, mannequins are synthesized (exact mode, default options) at the held-out body's
measurements from every set of 3, 4 and 5 of the other bodies, and compared with the held-out body's mesh:
volumetric IoU (intersection over union of the voxels, 5 mm grid: core.geometry.volume.voxel_iou) of the
mannequin's cushions (its convex pieces) and of its ellipsoids, the body moved by the registration its own RM
got (so both stand in the same frame). The held-out body's own RM (traced on it) is the ceiling. With the
reference body held out, the set of five is the shipped set. Prints a markdown table (and writes it with
--out).
Takes a few minutes.
"""

import argparse
import itertools
import pathlib
import sys

import numpy as np

from ellimann_addon.core.constants import REFERENCE_MEASUREMENTS
from ellimann_addon.core.fitting.reference_build import display_name
from ellimann_addon.core.geometry.volume import IOU_MARGIN, IOU_SPACING, BodyVolume, voxel_iou
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.manifest import Manifest, targets_range
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER, ReferenceSet
from ellimann_addon.core.synthesis.synthesize import synthesize_batch

from ..shipped.bodies import REFERENCE_BODY, body_measurements, load_labels, read_bodies
from ..shipped.build_reference import DEFAULT_REFMODELS, REFERENCE_RM
from ..shipped.reference_sets import TRACING_FOLDER

SIZES = (3, 4, 5)


def six_rms(refmodels, workers, build_set=None):
    """({stem: RM} of the six bodies, {stem: targets}, {stem: body -> RM shift}, {stem: BodyMesh}).

    ``build_set`` (tools/shipped/reference_sets.py, default the female set of the 40): whose base, bodies (its six, from
    ``refmodels``), targets and section heights."""
    from ellimann_addon.core.fitting.reference_build import build_reference_set

    if build_set is None:
        reference_body, rm_targets, fractions, folder = REFERENCE_BODY, REFERENCE_MEASUREMENTS, None, REFERENCE_FOLDER
    else:
        reference_body, rm_targets = build_set.reference_body, build_set.targets
        fractions, folder = build_set.fractions, build_set.out
    bodies = read_bodies(refmodels, (reference_body, *rm_targets))  # with their joints, as the shipped sets' RMs
    targets = {name: dict(row) for name, row in rm_targets.items()}
    # the reference body's targets: its own measurements (measured as refmodels/README.md says)
    if fractions is None:
        targets[reference_body] = body_measurements(bodies[reference_body], load_labels(refmodels))
    else:  # the labels of the traced body: every body shares its vertex order
        targets[reference_body] = body_measurements(bodies[reference_body], load_labels(TRACING_FOLDER), fractions)
    base = Mannequin.load(folder / "base_mannequin.json")
    built = build_reference_set(
        base,
        list(bodies.values()),
        targets,
        reference=REFERENCE_RM,
        workers=workers,
        progress=lambda f, text: print(f"  {f:4.0%} {text}", file=sys.stderr),
    )
    return built.mannequins, targets, built.report.shifts, bodies


def subset_set(rms, targets, names):
    """The reference set of the RMs ``names`` (their targets its ranges)."""
    chosen = {name: targets[name] for name in names}
    manifest = Manifest("held out", list(names), ranges_cm=targets_range(chosen), targets_cm=chosen)
    return ReferenceSet([rms[name] for name in names], names=list(names), manifest=manifest)


def held_out_table(rms, targets, shifts, bodies):
    """Rows {held-out stem: {"own": (cushions, ellipsoids), size: [(cushions, ellipsoids) per set]}}."""
    rows = {}
    for held in bodies:
        body = bodies[held]
        grid = BodyVolume(body.vertices + shifts[held], body.faces).grid(IOU_SPACING, margin=IOU_MARGIN)
        row = {"own": (voxel_iou(rms[held], grid=grid), voxel_iou(rms[held], cushions=False, grid=grid))}
        others = [name for name in bodies if name != held]
        request = np.array([[targets[held][k] for k in MEASUREMENTS]])
        for size in SIZES:
            row[size] = []
            for subset in itertools.combinations(others, size):
                reference = subset_set(rms, targets, subset)
                mannequin = synthesize_batch(reference, request, mode="exact").mannequin(0)
                row[size].append((voxel_iou(mannequin, grid=grid), voxel_iou(mannequin, cushions=False, grid=grid)))
        rows[held] = row
        print(
            f"  {held}: own RM {row['own'][0]:.3f}, "
            + ", ".join(f"N={size} {np.mean([v[0] for v in row[size]]):.3f}" for size in SIZES),
            file=sys.stderr,
        )
    return rows


def markdown(rows):
    def cell(values, which):
        values = [v[which] for v in values]
        if len(values) == 1:
            return f"{values[0]:.3f}"
        return f"{np.mean(values):.3f} ({min(values):.3f}-{max(values):.3f})"

    lines = []
    for which, label in ((0, "cushions"), (1, "ellipsoids")):
        lines += [
            f"Volumetric IoU of the {label} with the held-out body ({IOU_SPACING * 1e3:g} mm voxels); "
            "N = 3, 4: mean (min-max) over every set of that many of the other five bodies.",
            "",
            "| held-out body | own RM (ceiling) | N = 5 | N = 4 | N = 3 |",
            "|---|---|---|---|---|",
        ]
        for held, row in rows.items():
            lines.append(
                f"| {display_name(held)} | {row['own'][which]:.3f} | "
                + " | ".join(cell(row[size], which) for size in (5, 4, 3))
                + " |"
            )
        means = {size: np.mean([v[which] for row in rows.values() for v in row[size]]) for size in SIZES}
        own = np.mean([row["own"][which] for row in rows.values()])
        lines += [f"| **mean** | {own:.3f} | " + " | ".join(f"{means[size]:.3f}" for size in (5, 4, 3)) + " |", ""]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.figures.held_out", description=__doc__.split("\n")[0])
    parser.add_argument("--refmodels", type=pathlib.Path, default=DEFAULT_REFMODELS)
    parser.add_argument("--workers", type=int, default=2, help="processes building the six RMs")
    parser.add_argument("--out", type=pathlib.Path, help="also write the table to this markdown file")
    args = parser.parse_args(argv)
    rms, targets, shifts, bodies = six_rms(args.refmodels, args.workers)
    text = markdown(held_out_table(rms, targets, shifts, bodies))
    print(text)
    if args.out:
        args.out.write_text(text + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
