"""Exact mode on the skin with the six extra measurements (core.skin.exact): on bench/bench_skin_exact.py's grid
of requests (reference bodies' own measurements with and without their six extra ones, on both sets, and the
set's own extra ones 6 % up or down) the skin's mesh measures every one asked within 1 mm by the body-mesh
measurer's definitions, the five too; the skin's arms are the vertices of its arm pieces, so the measurer takes
an arm that touches the torso as an arm; a request no body can meet is refused in one line before any work."""

import numpy as np
import pytest

from bench.bench_skin_exact import GRID, grid_request
from ellimann_addon.core.constants import TABLE_2_5
from ellimann_addon.core.mannequin.skin_record import SkinSettings
from ellimann_addon.core.measure.extra import mannequin_extra_measurements
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.skin import exact
from ellimann_addon.core.skin.exact import MESH_TOLERANCE_CM, exact_skin
from ellimann_addon.core.skin.measure import body_measurements, mesh_measurements, skin_arms
from ellimann_addon.core.skin.surface import build_skin
from ellimann_addon.core.synthesis.extra_refine import ExtraRequestError
from ellimann_addon.core.synthesis.shipped import named_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize

PREVIEW = SkinSettings.at_level("preview")
# At the preview level (10 mm voxels) the tall chubby body's thighs fuse in the skin as soon as its hips are asked
# a few mm larger: the measurer then finds the crotch 5 cm lower, and its thigh and calf with it, and the loop
# ends 5 mm from the request; at the final level (5 mm) the thighs stay apart and the loop meets it in 4 rounds.
LEVEL = {("female", "tall_chubby", "own"): "final"}


@pytest.fixture(scope="module")
def sets():
    return {name: named_reference_set(name) for name in ("female", "male")}


def test_the_skin_s_arms_are_its_arm_pieces_and_the_measurer_takes_them_so(sets):
    # Table 2.5's second mannequin: narrow shoulders, the arms close to the torso below the upper-arm section
    mannequin = synthesize(sets["female"], TABLE_2_5[1])[0]
    skin = build_skin(mannequin, PREVIEW)
    arms = skin_arms(skin)
    left, right = (skin.vertices[arms[side]] for side in ("L", "R"))
    assert left[:, 0].min() > 0.0 and right[:, 0].max() < 0.0  # each arm on its side
    assert abs(len(left) - len(right)) <= 0.02 * len(left)
    measured = body_measurements(skin)
    assert measured.problems == []  # no section is "above the armpit": the arms are left out wherever they are
    on_mesh = mesh_measurements(skin)
    for key in MEASUREMENTS:  # the five as m_T's definitions on the mesh take them (the arms by their pieces)
        assert measured.values[key] == pytest.approx(on_mesh[key], abs=1e-6), key
    pieces = mannequin_extra_measurements(mannequin)
    # The arm found by its pieces measures as its pieces do (the skin adds little around an arm; the preview's
    # 10 mm voxels round the fingertip off a few mm); found by geometry alone, the arm's loop across it is cut
    # short where the arm meets the torso above the armpit.
    assert abs(measured.values["upper_arm"] - pieces["upper_arm"]) < 0.3
    assert abs(measured.values["arm_length"] - pieces["arm_length"]) < 0.5
    assert abs(skin.measure().values["upper_arm"] - pieces["upper_arm"]) > 1.0


@pytest.mark.slow
@pytest.mark.parametrize("set_name, body, extra", GRID, ids=[f"{s}-{b}-{e}" for s, b, e in GRID])
def test_exact_mode_on_the_skin_meets_the_five_and_the_six_asked_on_its_mesh(sets, set_name, body, extra):
    reference = sets[set_name]
    five, six = grid_request(reference, set_name, body, extra)
    mannequin = synthesize(reference, list(five.values()))[0]
    result = exact_skin(mannequin, SkinSettings.at_level(LEVEL.get((set_name, body, extra), "preview")), five, six)
    assert result.converged and result.misses() == []
    assert set(result.request) == set(MEASUREMENTS) | set(six)
    # measured again, independently, on the skin's own mesh
    on_mesh = {**mesh_measurements(result.skin), **body_measurements(result.skin).values}
    for key, wanted in {**five, **six}.items():
        assert abs(on_mesh[key] - wanted) <= MESH_TOLERANCE_CM, (key, on_mesh[key], wanted)
        assert result.skin_measured[key] == pytest.approx(on_mesh[key], abs=1e-9)
    # the pieces were asked for less than the skin measures: the blend adds to a girth
    assert any(result.pieces_measured[key] < wanted - MESH_TOLERANCE_CM for key, wanted in {**five, **six}.items())


def test_a_request_no_body_can_meet_is_refused_in_one_line_before_any_work(sets, monkeypatch):
    mannequin = sets["female"].mannequins[4]
    monkeypatch.setattr(exact, "build_skin", lambda *args: pytest.fail("a skin was built"))
    with pytest.raises(ExtraRequestError, match=r"^thigh 130 cm >= Hi 117 cm by 13\.00 cm: a thigh cannot be"):
        exact_skin(mannequin, PREVIEW, extra={"thigh": 130.0})
    with pytest.raises(ExtraRequestError, match=r"^wrist: not a measurement \(one of neck, upper_arm"):
        exact_skin(mannequin, PREVIEW, extra={"wrist": 15.0})
    with pytest.raises(ExtraRequestError, match=r"^neck \(Neck girth\) must be 15-80 cm, got nan$"):
        exact_skin(mannequin, PREVIEW, extra={"neck": float("nan")})


def test_without_extra_measurements_the_loop_is_the_five_s_own(sets, monkeypatch):
    """No extra measurement asked: the five's loop over the surface, the body-mesh measurer never run."""
    mannequin = sets["female"].mannequins[4]
    monkeypatch.setattr(exact, "body_measurements", lambda *args: pytest.fail("measured as a body mesh"))
    result = exact_skin(mannequin, PREVIEW, max_rounds=1)
    assert set(result.request) == set(result.skin_measured) == set(MEASUREMENTS)
    assert np.isfinite(list(result.skin_measured.values())).all()
