"""The shipped reference data is what its build tool makes from ../shared/refmodels today, on any CPU.

A change to fitting, cleaning or refinement that moves the reference mannequins fails here until
``python -m tools.shipped.build_reference`` is run again and its output committed (JSON, .blend, docs).
Another CPU's BLAS rounds differently in the last bits; the build must not amplify that. So the one
build here (about three minutes) is run with every body vertex moved by JITTER, a rounding-level change
of the inputs, and must still pass ``--check``: land within CHECK_TOLERANCE of every shipped number and
print the same docs. It fails if the code moved the mannequins and if the build amplifies rounding.
"""

import numpy as np
import pytest

from ellimann_addon.core.mannequin.model import Mannequin
from tools.shipped import build_reference

JITTER = 1e-9  # m: a rounding-level change of the inputs
SHIPPED = build_reference.REPO / "reference_blends"
DOCS = build_reference.REPO / "docs"


@pytest.fixture(scope="module")
def perturbed():
    """(base, rms, report) built from the bodies with every vertex moved by up to JITTER."""
    return build_reference.build(log=lambda *_: None, jitter=JITTER)


@pytest.mark.slow
def test_the_build_from_rounding_level_perturbed_bodies_passes_check(perturbed, monkeypatch, capsys):
    """The shipped data and docs are the build tool's output, and a rounding-level change of its inputs moves no
    shipped number beyond CHECK_TOLERANCE (what another CPU's last bits would do)."""
    monkeypatch.setattr(build_reference, "build", lambda *args, **kwargs: perturbed)
    status = build_reference.main(["--check", "--no-blend"])
    out = capsys.readouterr().out
    assert status == 0, out[out.index("built in") :]
    assert "identical to the files in" in out


@pytest.mark.slow
def test_every_shipped_number_is_within_tolerance_of_the_perturbed_build(perturbed):
    base, rms, _ = perturbed
    shipped = _shipped()
    moved = {
        stem: max(
            float(np.abs(getattr(m, attr) - getattr(shipped[stem], attr)).max())
            for attr in ("rotation", "center", "semi_axes")
        )
        for stem, m in {build_reference.BASE_FILE: base, **rms}.items()
    }
    assert max(moved.values()) <= build_reference.CHECK_TOLERANCE, moved


def _shipped():
    return {
        stem: Mannequin.load(SHIPPED / f"{stem}.json")
        for stem in (build_reference.BASE_FILE, *build_reference.RM_BODIES)
    }


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
    changed = text[: first.start()] + f"{float(first.group()) + 0.5:.{len(first.group().partition('.')[2])}f}"
    assert build_reference.docs_differ(text, changed + text[first.end() :])
