"""The shipped Base Mannequin and Reference Mannequins (reference_blends/*.json), built by
tools/shipped/build_reference."""

import pathlib

import numpy as np
import pytest

from ellimann_addon.core.constants import REFERENCE_MEASUREMENTS
from ellimann_addon.core.geometry.ellipsoid import section_at_height
from ellimann_addon.core.geometry.frames import axis_agreement, is_rotation
from ellimann_addon.core.mannequin.clean import asymmetry, landmark_indices
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.topology import NAME_PATTERN
from ellimann_addon.core.measure.tailor import section_heights
from ellimann_addon.core.measurements import MEASUREMENTS

FOLDER = pathlib.Path(__file__).resolve().parents[3] / "reference_blends"
DOCS = pathlib.Path(__file__).resolve().parents[3] / "docs"
RM_NAMES = tuple(REFERENCE_MEASUREMENTS)
REFERENCE_RM = "average"  # the RM the others' axes were relabelled against
TOLERANCE = 0.005  # the issue: m_T within 0.5% of Table 2.3
# Measured on the shipped data: 0.9530 (10.a Trapezius); every other part agrees better.
MIN_AXIS_AGREEMENT = 0.93
# m: consecutive cushions of a limb touch (tools/shipped/coverage.py measures 0 on the shipped data)
GAP_TOLERANCE = 1e-3


@pytest.fixture(scope="module")
def base():
    return Mannequin.load(FOLDER / "base_mannequin.json")


@pytest.fixture(scope="module")
def rms():
    return {name: Mannequin.load(FOLDER / f"{name}.json") for name in RM_NAMES}


def everything(base, rms):
    return [("base_mannequin", base), *rms.items()]


def test_files_load_validate_and_have_their_roles(base, rms):
    assert base.role == "base" and base.check() is base
    for name, rm in rms.items():
        assert rm.role == "reference" and rm.check() is rm
        assert rm.measurements == REFERENCE_MEASUREMENTS[name]


def test_every_reference_mannequin_has_the_base_topology(base, rms):
    assert 30 <= len(base.topology) <= 40
    for rm in rms.values():
        assert rm.topology == base.topology
        assert rm.topology.mismatch(base.topology) == []


def test_topology_has_the_registration_landmarks_and_a_whole_body(base):
    labels = {NAME_PATTERN.match(n).group("label") for n in base.topology.names}
    assert {
        "Trapezius",
        "Cranium",
        "Breast",
        "Thorax",
        "Rectus Abdominalis",
        "Pelvis",
        "Thigh",
        "Foot",
        "Upper Arm",
        "Forearm",
        "Hand",
    } <= labels
    trapezius = [base.topology.names[i] for i in landmark_indices(base.topology)]
    assert sorted(trapezius) == ["10.a Trapezius.L", "10.a Trapezius.R"]
    for part in base.topology:
        if part.region in ("arms", "hands"):
            assert not part.girth
        assert "He" in part.depends


def test_right_handed_symmetric_and_registered(base, rms):
    for name, m in everything(base, rms):
        assert np.all(is_rotation(m.rotation, tol=1e-9)), name
        assert asymmetry(m) < 1e-9, name
        floor = section_heights(m.rotation, m.center, m.semi_axes)[0]
        assert abs(float(floor)) < 1e-9, name
        landmark = m.center[landmark_indices(m.topology)].mean(axis=0)
        assert np.allclose(landmark[:2], 0.0, atol=1e-9), name


@pytest.mark.parametrize("name", RM_NAMES)
def test_m_t_meets_table_2_3(rms, name):
    measured = rms[name].measure()
    for key in MEASUREMENTS:
        target = REFERENCE_MEASUREMENTS[name][key]
        assert abs(measured[key] / target - 1.0) <= TOLERANCE, f"{name} {key}: m_T {measured[key]:.3f} vs {target}"


def test_corresponding_ellipsoids_have_consistent_axis_labels(rms):
    reference = rms[REFERENCE_RM]
    smallest = min(float(axis_agreement(rm.rotation, reference.rotation).min()) for rm in rms.values())
    assert smallest >= MIN_AXIS_AGREEMENT


def crossing(mannequin):
    _, _, heights = section_heights(mannequin.rotation, mannequin.center, mannequin.semi_axes)
    out = {}
    for key in ("Sh", "Br", "Wa", "Hi"):
        _, _, hit = section_at_height(mannequin.rotation, mannequin.center, mannequin.semi_axes, heights[key])
        if key != "Sh":
            hit &= mannequin.topology.girth_mask
        out[key] = {NAME_PATTERN.match(n).group("label") for n, h in zip(mannequin.topology.names, hit) if h}
    return out


def test_each_section_cuts_the_parts_that_make_that_measurement(base, rms):
    for name, m in everything(base, rms):
        cut = crossing(m)
        assert "Deltoid" in cut["Sh"], name
        assert {"Breast", "Thorax"} <= cut["Br"], name
        assert {"Rectus Abdominalis", "Lower Back", "Oblique"} <= cut["Wa"], name
        assert {"Pelvis", "Gluteus", "Thigh"} <= cut["Hi"], name
        assert not {"Cranium", "Neck", "Calf", "Foot"} & set().union(*cut.values()), name


def test_girth_sections_cut_only_parts_that_depend_on_their_measurement(base, rms):
    # The segmented scheme interpolates each part on the measurements it depends on: a breast part
    # reaching down into the waist section would make the waist follow the requested breast.
    for name, m in everything(base, rms):
        _, _, heights = section_heights(m.rotation, m.center, m.semi_axes)
        for key in ("Br", "Wa", "Hi"):
            _, _, hit = section_at_height(m.rotation, m.center, m.semi_axes, heights[key])
            strays = [p.name for p, h in zip(m.topology, hit & m.topology.girth_mask) if h and key not in p.depends]
            assert strays == [], f"{name} {key}"


def test_docs_list_every_part_and_the_shipped_measurements(base, rms):
    topology = (DOCS / "topology.md").read_text(encoding="utf-8")
    assert all(f"| {name} |" in topology for name in base.topology.names)
    table = (DOCS / "reference_mannequins.md").read_text(encoding="utf-8")
    for rm in rms.values():
        measured = rm.measure()
        assert " | ".join(f"{measured[k]:.2f}" for k in MEASUREMENTS) in table


def test_shipped_topology_is_the_build_tool_topology(base):
    from tools.shipped.reference_topology import topology

    assert topology() == base.topology


def test_the_cushions_of_every_limb_chain_touch(base, rms):
    from tools.shipped.coverage import chain_gaps

    for name, m in everything(base, rms):
        gaps = chain_gaps(m, cushions=True)
        for chain in ("leg", "arm", "neck, head"):
            assert max(gaps[chain]) <= GAP_TOLERANCE, f"{name} {chain}: {gaps[chain]}"
