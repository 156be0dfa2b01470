"""The fine topology's definition (tools/shipped/reference_topology_fine.py) and tools: its parts are the 40 and
more, each new part on a bone and traced from enough vertices; the cloth's gap (tools/figures/cloth_gap.py) on shapes
whose answer is known; a base missing one recorded selection is refused by ``references build`` in one line, nothing
written; exact mode meets the measurements of bodies the set has not seen. That the shipped fine sets are what
tools/shipped/build_fine.py builds is ``python -m tools.shipped.build_fine --check`` (two builds of several minutes:
not in the test matrix's budget).
"""

import numpy as np
import pytest

from devkit.cli_runs import assert_one_line_error, run
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry.mesh import icosphere
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.skeleton import PART_BONES, part_label
from ellimann_addon.core.mannequin.topology import Part, Topology
from ellimann_addon.core.measure.body import measure_body_mesh
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.shipped import FEMALE_FINE_SET, SHIPPED_SETS, named_reference_set
from ellimann_addon.core.synthesis.synthesize import EXACT_TOLERANCE, synthesize_batch
from tools.figures.cloth_gap import surface_gap, weighted_percentile
from tools.shipped import reference_topology as rt
from tools.shipped.bodies import REFERENCE_BODY, RM_BODIES, load_labels
from tools.shipped.build_reference import trace_reference
from tools.shipped.reference_sets import FEMALE, MALE, TRACING_FOLDER
from tools.shipped.reference_topology_fine import EXTRA_SPECS, FINE_CHAINS, FINE_SPECS


def test_the_fine_topology_is_the_40_and_the_new_parts_each_on_a_bone():
    fine, coarse = rt.topology(FINE_SPECS), rt.topology()
    assert fine.names[: len(coarse)] == coarse.names
    assert all(fine.parts[fine.index[p.name]] == p for p in coarse)
    new = {part_label(name) for name in fine.names[len(coarse) :]}
    assert new == {spec.label for spec in EXTRA_SPECS} and new <= set(PART_BONES)
    labels = {part_label(name) for name in fine.names}
    assert {label for chain in FINE_CHAINS.values() for link in chain for label in link} <= labels


def test_every_fine_part_is_traced_from_enough_vertices_of_the_reference_body():
    body = read_obj(TRACING_FOLDER / f"{REFERENCE_BODY}.obj", up="z")
    traces, _ = trace_reference(body, load_labels(TRACING_FOLDER), FINE_SPECS)  # raises below 8 vertices
    assert set(traces) == set(rt.topology(FINE_SPECS).names)
    shipped = Mannequin.load(SHIPPED_SETS[FEMALE_FINE_SET] / "base_mannequin.json").traces
    for name, trace in traces.items():  # the shipped base recorded these selections
        assert np.array_equal(shipped[name].vertices, trace.vertices), name


def _ball(radius):
    topology = Topology([Part("1.a Ball", "C", "body", True, ("He",))])
    return Mannequin(topology, np.eye(3)[None], np.zeros((1, 3)), np.full((1, 3), radius))


def test_the_cloth_gap_of_a_sphere_in_a_larger_sphere_is_the_difference_of_radii():
    vertices, faces = icosphere(4)
    gap = surface_gap(_ball(0.08), 0.1 * vertices, faces)
    assert gap["outside"] == 1.0
    for key in ("median", "p95", "outside_median", "outside_p95"):
        assert gap[key] == pytest.approx(0.02, abs=1e-12)
    inside = surface_gap(_ball(0.12), 0.1 * vertices, faces)
    assert inside["outside"] == 0.0 and inside["median"] == inside["p95"] == inside["outside_p95"] == 0.0


def test_weighted_percentiles_weigh_by_area():
    values, weights = np.array([3.0, 1.0, 2.0]), np.array([1.0, 1.0, 8.0])
    assert weighted_percentile(values, weights, 50) == 2.0
    assert weighted_percentile(values, weights, 95) == 3.0
    assert weighted_percentile(values, np.ones(3), 10) == 1.0


def test_a_fine_base_missing_one_recorded_selection_is_refused_in_one_line(tmp_path, capsys):
    base = Mannequin.load(SHIPPED_SETS[FEMALE_FINE_SET] / "base_mannequin.json")
    traces = dict(base.traces)
    del traces["21.a Armpit.L"]
    base.copy(traces=traces).save(tmp_path / "base.json")
    targets = tmp_path / "targets.csv"
    rows = [f"{n}," + ",".join(f"{FEMALE.targets[n][k]:g}" for k in MEASUREMENTS) for n in RM_BODIES]
    targets.write_text("name," + ",".join(MEASUREMENTS) + "\n" + "\n".join(rows) + "\n")
    bodies = [str(TRACING_FOLDER / f"{n}.obj") for n in RM_BODIES[:3]]
    out = tmp_path / "set"
    args = ["references", "build", "--base", str(tmp_path / "base.json"), "--targets", str(targets), "--up", "z"]
    code, _, err = run([*args, "--bodies", *bodies, "-o", str(out)], capsys)
    assert_one_line_error(code, err, "'21.a Armpit.L' has no recorded selection", "Fit Ellipsoid")
    assert not out.exists()


@pytest.mark.parametrize("build_set", [FEMALE, MALE], ids=["female-fine", "male-fine"])
def test_exact_mode_meets_the_measurements_of_bodies_the_fine_sets_have_not_seen(build_set):
    """Each set's neutral body (none of its RMs') measured as a scan is measured: the fine set's exact mode meets its
    measurements to 0.001 %, as it meets the mannequins' (the 243 grid: tests/core/synthesis/test_fine_set.py). One
    body per set: reading and measuring a body mesh is what takes the time."""
    _assert_exact_on_bodies(build_set, [build_set.reference_body])


def _assert_exact_on_bodies(build_set, names):
    reference = named_reference_set(f"{build_set.name}-fine")
    requests = []
    for name in names:
        body = read_obj(build_set.refmodels / f"{name}.obj", up="z")
        found = measure_body_mesh(body.vertices, body.faces, build_set.fractions).values
        requests.append([found[key] for key in MEASUREMENTS])
    result = synthesize_batch(reference, np.array(requests), mode="exact")
    assert result.converged.all() and result.relative_error().max() <= 100.0 * EXACT_TOLERANCE
