"""The shipped reference data is what its build tool makes from ../shared/refmodels today, on any CPU.

A change to fitting, cleaning or refinement that moves the reference mannequins fails here until
``python -m tools.build_reference`` is run again and its output committed (JSON, .blend, docs).
Another CPU's BLAS rounds differently in the last bits; the build must not amplify that, so it is
also run with every body vertex moved by JITTER and must land within PERTURBED_TOLERANCE.
"""

import numpy as np
import pytest

from ellimann_addon.core.mannequin import Mannequin
from tools import build_reference

JITTER = 1e-9  # m: a rounding-level change of the inputs
PERTURBED_TOLERANCE = 1e-6  # m: how far it may move any shipped number
SHIPPED = build_reference.REPO / "reference_blends"
DOCS = build_reference.REPO / "docs"


@pytest.fixture(scope="module")
def builds():
    """{jitter: (base, rms, report)}: the build as shipped and perturbed (two builds, ~1 min each)."""
    return {jitter: build_reference.build(log=lambda *_: None, jitter=jitter) for jitter in (0.0, JITTER)}


def _mannequins(build):
    base, rms, _ = build
    return {build_reference.BASE_FILE: base, **rms}


@pytest.mark.slow
def test_shipped_reference_data_and_docs_are_the_build_tools_output(builds, monkeypatch, capsys):
    monkeypatch.setattr(build_reference, "build", lambda *args, **kwargs: builds[0.0])
    status = build_reference.main(["--check", "--no-blend"])
    out = capsys.readouterr().out
    assert status == 0, out[out.index("built in"):]
    assert "identical to the files in" in out


@pytest.mark.slow
def test_a_rounding_level_perturbation_of_the_bodies_moves_no_shipped_number(builds):
    plain, perturbed = _mannequins(builds[0.0]), _mannequins(builds[JITTER])
    moved = {stem: max(float(np.abs(getattr(plain[stem], attr) - getattr(perturbed[stem], attr)).max())
                       for attr in ("rotation", "center", "semi_axes")) for stem in plain}
    assert max(moved.values()) <= PERTURBED_TOLERANCE, moved


@pytest.mark.slow
def test_check_passes_a_rebuild_that_differs_by_rounding(builds):
    base, rms, report = builds[JITTER]
    docs = build_reference.generated_docs(base, rms, report)
    assert build_reference.check(base, rms, docs, SHIPPED, DOCS) == []


def _shipped():
    return {stem: Mannequin.load(SHIPPED / f"{stem}.json")
            for stem in (build_reference.BASE_FILE, *build_reference.RM_BODIES)}


@pytest.mark.parametrize("shift, flagged", [(1e-8, False), (2 * build_reference.CHECK_TOLERANCE, True)])
def test_check_flags_numbers_moved_beyond_its_tolerance(shift, flagged):
    mannequins = _shipped()
    base = mannequins.pop(build_reference.BASE_FILE)
    average = mannequins["average"]
    center = average.center.copy()
    center[3, 1] += shift
    mannequins["average"] = average.copy(center=center)
    problems = build_reference.check_shipped(base, mannequins, SHIPPED)
    assert problems == ([f"average: center differs by up to {shift:.3g}"] if flagged else [])


def test_docs_are_compared_at_their_printed_precision():
    text = (DOCS / "reference_mannequins.md").read_text()
    assert not build_reference.docs_differ(text, text)
    row = "| Average | 85.2% |"
    assert not build_reference.docs_differ(row, "| Average | 85.3% |")  # rounded the other way
    assert build_reference.docs_differ(row, "| Average | 85.4% |")
    assert build_reference.docs_differ(row, "| Average | 85.20% |")
    assert build_reference.docs_differ(row, "| Average | -85.2% |")
    assert build_reference.docs_differ(row, "| Small Slim | 85.2% |")
    # a real change somewhere in the shipped docs is found
    first = next(m for m in build_reference._NUMBER.finditer(text) if "." in m.group())
    changed = text[:first.start()] + f"{float(first.group()) + 0.5:.{len(first.group().partition('.')[2])}f}"
    assert build_reference.docs_differ(text, changed + text[first.end():])
