"""The shipped sets on the fine topology (reference_blends/female-fine/, reference_blends/male-fine/): the 40's rules
hold on every part (mirror twins, right-handed frames, one bone each, girth sections cut only the parts that follow
their measurement), the RMs meet the same targets as their 40-part twins at the same heights, exact mode meets the
243 grid, and mannequins of the two topologies are never mixed: a set holding both, a mannequin measured with the
other topology's set and a live target of the other topology are refused in one line, nothing written."""

import itertools
import json
import shutil

import numpy as np
import pytest

from devkit.cli_runs import assert_one_line_error, run
from ellimann_addon.core.constants import GIRTHS, quartile_points
from ellimann_addon.core.errors import ReferenceSetError
from ellimann_addon.core.fitting.reference_build import cleanliness_problems
from ellimann_addon.core.geometry.ellipsoid import axis_extent, section_at_height
from ellimann_addon.core.geometry.frames import is_rotation
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.skeleton import PARENTS, bone_names, cross_joint_pairs, part_bones
from ellimann_addon.core.measure.tailor import section_heights
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.reference_set import load_reference_set
from ellimann_addon.core.synthesis.shipped import (
    FEMALE_FINE_SET,
    FEMALE_SET,
    MALE_FINE_SET,
    MALE_SET,
    SHIPPED_SETS,
    named_reference_set,
)
from ellimann_addon.core.synthesis.synthesize import EXACT_TOLERANCE, synthesize_batch

TWINS = {FEMALE_FINE_SET: FEMALE_SET, MALE_FINE_SET: MALE_SET}


@pytest.fixture(scope="module", params=sorted(TWINS))
def fine(request):
    return named_reference_set(request.param)


def test_the_fine_topology_holds_the_40_and_more(fine):
    coarse = named_reference_set(TWINS[fine.name]).topology
    assert len(fine.topology) > len(coarse)
    for part in coarse:
        assert fine.topology.parts[fine.topology.index[part.name]] == part  # the same side, region, flags, partner
    assert not fine.topology.problems()  # names, sides, mirror twins, partners
    girths = fine.topology.dependency_mask[:, [MEASUREMENTS.index(key) for key in GIRTHS]]
    assert girths.sum(axis=1).max() == 1  # no part follows two girths: their factors would be tied (exact mode)


def test_every_part_rides_on_one_bone_and_cushions_are_on_one_bone_or_across_a_joint(fine):
    topology = fine.topology
    bones = part_bones(topology)
    assert len(bones) == len(topology)
    for i, j in topology.cushion_pairs:
        a, b = bones[i], bones[j]
        assert a == b or PARENTS[b] == a or PARENTS[a] == b, (topology.names[i], topology.names[j])
    assert all(joint >= 0 for _, _, joint in cross_joint_pairs(topology))
    named = bone_names(topology)
    for name, bone in named.items():  # a part and its mirror twin ride on mirrored bones
        if name.endswith(".L"):
            assert named[name[:-2] + ".R"] == (f"R{bone[1:]}" if bone.startswith("L_") else bone), name


def test_the_rms_are_clean_right_handed_and_meet_their_40_twins_targets(fine):
    coarse = named_reference_set(TWINS[fine.name])
    assert fine.names == coarse.names and fine.section_fractions == coarse.section_fractions
    assert np.array_equal(fine.measurements, coarse.measurements) and fine.ranges == coarse.ranges
    for name, mannequin in zip(fine.names, fine.mannequins):
        assert mannequin.reference_set == fine.name and mannequin.joints is not None
        assert np.all(is_rotation(mannequin.rotation, 1e-9)) and not cleanliness_problems(mannequin)
        measured = mannequin.measure()
        for k, key in enumerate(MEASUREMENTS):
            assert abs(measured[key] / fine.measurements[fine.names.index(name), k] - 1.0) < EXACT_TOLERANCE
    base = Mannequin.load(SHIPPED_SETS[fine.name] / "base_mannequin.json")
    assert base.role == "base" and base.reference_set == fine.name and base.topology == fine.topology
    assert set(base.traces) == set(base.topology.names)  # every part's selection recorded


def test_each_girth_section_cuts_only_parts_that_follow_its_measurement(fine):
    """The 40's rule on every part: a girth part keeps clear of the sections of measurements it does not depend
    on, so synthesis' segmented IDW and exact mode's factors act on the parts each measurement is taken on."""
    girth, depends = fine.topology.girth_mask, fine.topology.dependency_mask
    for mannequin in fine.mannequins:
        _, _, heights = section_heights(
            mannequin.rotation, mannequin.center, mannequin.semi_axes, mannequin.section_fractions
        )
        for key in GIRTHS:
            _, _, hit = section_at_height(mannequin.rotation, mannequin.center, mannequin.semi_axes, heights[key])
            cut = hit & girth
            follows = depends[:, MEASUREMENTS.index(key)]
            assert np.all(follows[cut]), (mannequin.name, key, np.array(fine.topology.names)[cut & ~follows])


@pytest.mark.parametrize("name", SHIPPED_SETS)
def test_a_part_on_the_height_alone_is_about_as_wide_on_every_rm(name):
    """IDW weighs a part by the measurements it depends on only: a part on He alone takes the RMs of the request's
    height whatever its build, so its width must not follow the build. Its half-width (x extent) spans at most 1.5x
    over the RMs (the heads and necks: at most 1.38x, the fine Jaw); the fine Base of Neck on He alone spanned 2.3x
    (5.6-13 cm), so a slim request of Tall Chubby's height wore Tall Chubby's, 26 cm across."""
    reference = named_reference_set(name)
    on_height = np.nonzero(reference.topology.dependency_mask.sum(axis=1) == 1)[0]
    assert len(on_height)
    widths = axis_extent(reference.rotation[:, on_height], reference.semi_axes[:, on_height], 0)
    spans = widths.max(axis=0) / widths.min(axis=0)
    assert spans.max() <= 1.5, dict(zip(np.array(reference.topology.names)[on_height], spans.round(2)))


@pytest.mark.parametrize("name", SHIPPED_SETS)
def test_fine_parts_keep_clear_of_the_bodys_triangles_and_the_40s_of_its_vertices(name):
    """A thin fine part slipped out between the vertices of a coarse mesh (Tall Chubby's Upper Gluteus, 22.7 mm out
    of the body): the fine bases record the spacing of the wall points on the triangles for every part but the
    mittens, which a set rebuilt from them fits with; the 40 keep the vertices alone, as they were traced."""
    base = Mannequin.load(SHIPPED_SETS[name] / "base_mannequin.json")
    spacing = {trace.fit.wall_spacing for trace in base.traces.values() if not trace.fit.mitten}
    assert spacing == ({0.01} if name in TWINS else {None})
    assert all(trace.fit.wall_spacing is None for trace in base.traces.values() if trace.fit.mitten)


@pytest.mark.parametrize("name", SHIPPED_SETS)
def test_fine_parts_pay_for_the_outside_they_cover_and_the_40s_do_not(name):
    """Placed for the inside they fill alone, the fine parts bulged out of the body wherever the depth let them
    (docs/topology_fine_tried.md): the fine bases record what covering the outside costs for every part but the
    mittens; the 40 pay nothing, as they were traced."""
    base = Mannequin.load(SHIPPED_SETS[name] / "base_mannequin.json")
    costs = {trace.fit.outside_cost for trace in base.traces.values() if not trace.fit.mitten}
    assert costs == ({1.0} if name in TWINS else {None})
    assert all(trace.fit.outside_cost is None for trace in base.traces.values() if trace.fit.mitten)


def test_the_manifest_names_the_fine_set_and_its_topology(fine):
    manifest = json.loads((SHIPPED_SETS[fine.name] / "reference_set.json").read_text(encoding="utf-8"))
    assert manifest["name"] == fine.name and manifest["sex"] == named_reference_set(TWINS[fine.name]).manifest.sex
    assert f"{len(fine.topology)} parts" in manifest["provenance"]["topology"]


def test_exact_mode_meets_the_243_grid_on_the_fine_sets(fine):
    grid = np.array(list(itertools.product(*[quartile_points(k, fine.ranges) for k in MEASUREMENTS])))
    result = synthesize_batch(fine, grid, mode="exact")
    assert result.converged.all()
    assert result.relative_error().max() <= 100.0 * EXACT_TOLERANCE


def _mixed_folder(tmp_path):
    """The female set's folder with one RM replaced by its fine twin."""
    folder = tmp_path / "mixed"
    shutil.copytree(SHIPPED_SETS[FEMALE_SET], folder, ignore=shutil.ignore_patterns("*.blend"))
    shutil.copy(SHIPPED_SETS[FEMALE_FINE_SET] / "tall_slim.json", folder / "tall_slim.json")
    return folder


def test_a_set_mixing_topologies_is_refused_in_one_line(tmp_path, capsys):
    folder = _mixed_folder(tmp_path)
    with pytest.raises(ReferenceSetError, match="one topology") as info:
        load_reference_set(folder)
    assert "tall_slim.json" in str(info.value) and "\n" not in str(info.value)
    out = tmp_path / "m.json"
    request = ["--he", "160", "--sh", "40", "--br", "100", "--wa", "80", "--hi", "100"]
    code, _, err = run(["synth", *request, "--references", str(folder), "-o", str(out)], capsys)
    assert_one_line_error(code, err, "tall_slim.json", "one topology")
    assert not out.exists()


@pytest.mark.parametrize("mannequin_set, references", [(FEMALE_SET, FEMALE_FINE_SET), (MALE_FINE_SET, MALE_SET)])
def test_a_mannequin_measured_with_the_other_topologys_set_is_refused(mannequin_set, references, capsys):
    path = SHIPPED_SETS[mannequin_set] / "average.json"
    code, out, err = run(["measure", str(path), "--references", references], capsys)
    assert_one_line_error(code, err, "average.json", "parts", "one topology")
    assert not out
    code, out, _ = run(["measure", str(SHIPPED_SETS[references] / "average.json"), "--references", references], capsys)
    assert code == 0 and "He" in out
