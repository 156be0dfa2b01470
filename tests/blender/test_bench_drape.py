"""The drape bench runs end to end on a tiny setting (its figures come from `make bench`, not from here)."""

import pytest

from bench import bench_drape
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.synthesis.synthesize import REFERENCE_FOLDER

BODY = bench_drape.REFMODELS / f"{bench_drape.BODY}.obj"  # ../shared/refmodels, beside the repository (CI too)


@pytest.mark.slow
def test_drape_bench_prints_its_table_and_the_resolution_verdict(capsys):
    sweep = tuple(s for s in bench_drape.SWEEP if s[0] in ("cushions L1/L1", "cushions L2/L2", "ellipsoids L1"))
    body = read_obj(BODY, up="z")
    bench_drape.compare(
        Mannequin.load(REFERENCE_FOLDER / "average.json"),
        body.vertices,
        body.faces,
        frames=3,
        repeat=1,
        sweep=sweep,
        kinds=("tube_dress",),
        skins=("preview",),
    )
    out = capsys.readouterr().out
    rows = [line[:16].strip() for line in out.splitlines() if " | " in line and "triangles" not in line]
    assert rows == ["dense body", "cushions L1/L1", "cushions L2/L2", "ellipsoids L1", "skin preview"]
    assert "cushions" in out and ("best speed at equal fit" in out or "no resolution fits" in out)
    assert "ellipsoids: fewer than two resolutions, no comparison" in out
    assert "skin: fewer than two resolutions, no comparison" in out
