"""Dev tool (not shipped): a body's twin synthesized from the five measurements and from all it measures,
stood in the body as bench_scan stands it, the body a ghost over each (docs/images/twin_five_vs_all.png).

    .venv/bin/python -m tools.pictures.twin_picture [--bodies small_chubby tall_slim] [--out PNG]
"""

import argparse
import tempfile
from pathlib import Path

from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry.volume import IOU_MARGIN, BodyVolume
from ellimann_addon.core.measure.body import measure_body_mesh
from ellimann_addon.core.measure.extra import split_measurements
from ellimann_addon.core.synthesis.shipped import named_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize_extra
from tools.figures.overlap import standing_in
from tools.pictures import render
from tools.shipped.build_reference import DEFAULT_REFMODELS

SPACING = 0.005  # m, bench_scan's grid


def twins(name, reference):
    """(five-measurement twin, all-measurement twin) of body ``name``, each stood in the body."""
    body = read_obj(DEFAULT_REFMODELS / f"{name}.obj", up="z")
    found = measure_body_mesh(body.vertices, body.faces).values
    five, extra = split_measurements(found)
    grid = BodyVolume(body.vertices, body.faces).grid(SPACING, margin=IOU_MARGIN)
    return tuple(standing_in(grid, synthesize_extra(reference, five, given)[0]) for given in ({}, extra))


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.pictures.twin_picture", description=__doc__.splitlines()[0])
    parser.add_argument("--bodies", nargs="+", default=["small_chubby", "tall_slim"])
    parser.add_argument(
        "--out", type=Path, default=Path(__file__).resolve().parents[2] / "docs" / "images" / "twin_five_vs_all.png"
    )
    args = parser.parse_args(argv)
    reference = named_reference_set("female")
    with tempfile.TemporaryDirectory() as folder:
        files, ghosts = [], []
        for name in args.bodies:
            for label, twin in zip(("five", "all"), twins(name, reference)):
                path = Path(folder) / f"{name} {label}.json"
                twin.copy(name=f"{name}, {label}").save(path)
                files.append(path)
                ghosts.append(DEFAULT_REFMODELS / f"{name}.obj")
        return render.main(
            [
                "mannequins",
                *map(str, files),
                *sum((["--ghost", str(g)] for g in ghosts), []),
                "--side-too",
                "--out",
                str(args.out),
            ]
        )


if __name__ == "__main__":
    from ellimann_addon.blender.services import teardown

    teardown.exit_with(main())
