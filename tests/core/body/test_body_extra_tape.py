"""The extras' tape (core.body.extra_tape): whole, it reads the six as measure_body_mesh does to the last bit (the
neck square to a given tilt, or searched) on bodies of the shipped topology, the bank's 160 among them; in a window
about the last extremes it finds the same extremes on a body moved a little; the legs' own triangles stand for the
measurer's blobs only where they may."""

import numpy as np
import pytest

from ellimann_addon.core.body.extra_tape import ExtraTape, leg_masks
from ellimann_addon.core.measure.body import StandingBody, measure_body_mesh
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS
from ellimann_addon.core.synthesis.bodies import load_set_bodies
from ellimann_addon.core.synthesis.shipped import reference_folder
from tools.shipped.reference_sets import SHARED

TILT = 0.35  # radians forward: a neck axis's tilt as the bodies' joints give (0.3-0.45)


@pytest.fixture(scope="module", params=("female", "male"))
def bodies(request):
    return load_set_bodies(reference_folder(request.param))


def tape_of(bodies):
    return ExtraTape(bodies.faces, bodies.arms, leg_masks(bodies.region, bodies.region_names), bodies.fractions)


def whole_measurer(bodies, vertices, tilt):
    found = measure_body_mesh(vertices, bodies.faces, bodies.fractions, neck_tilt=tilt, arms=bodies.arms).values
    return {key: found[key] for key in EXTRA_MEASUREMENTS}


def test_whole_it_reads_the_six_as_the_measurer_to_the_last_bit(bodies):
    tape = tape_of(bodies)
    for i in (0, 3):
        vertices = bodies.vertices(i)
        for tilt in (TILT, None):  # a given tilt, and the tilt searched as on a scan
            assert tape.read(vertices, EXTRA_MEASUREMENTS, tilt)[0] == whole_measurer(bodies, vertices, tilt)


@pytest.mark.slow
def test_whole_it_reads_the_bank_s_bodies_as_the_measurer_to_the_last_bit(bodies):
    """The 80 bodies of ../shared/bodies of the set's sex, every 4th (a few seconds each by the measurer)."""
    tape = tape_of(bodies)
    sex = "male" if bodies.fractions["Wa"] != 0.645 else "female"
    bank = np.load(SHARED / "bodies" / f"{sex}.npz")["vertices"]
    for vertices in bank[::4].astype(float):
        assert tape.read(vertices, EXTRA_MEASUREMENTS, TILT)[0] == whole_measurer(bodies, vertices, TILT)


def test_a_window_about_the_last_extremes_finds_them_again_on_a_body_moved_a_little(bodies):
    tape = tape_of(bodies)
    rest = bodies.vertices(4)
    _, marks = tape.read(rest, EXTRA_MEASUREMENTS, TILT)
    moved = rest * [1.01, 1.02, 1.005]  # a little wider, deeper and taller
    whole = tape.read(moved, EXTRA_MEASUREMENTS, TILT)[0]
    window = tape.read(moved, EXTRA_MEASUREMENTS, TILT, marks)[0]
    assert max(abs(window[key] - whole[key]) for key in EXTRA_MEASUREMENTS) < 0.005  # cm: 0.05 mm
    coarse = tape.read(moved, EXTRA_MEASUREMENTS, TILT, coarse=True)[0]
    assert max(abs(coarse[key] - whole[key]) for key in EXTRA_MEASUREMENTS) < 0.1


def test_only_the_extras_asked_are_read(bodies):
    tape = tape_of(bodies)
    found, marks = tape.read(bodies.vertices(0), ["calf", "He"], TILT)
    assert list(found) == ["calf"] and set(marks.calf) == {"L", "R"} and not np.isfinite(marks.neck)


def test_the_legs_own_triangles_stand_for_the_measurer_s_only_below_the_crotch(bodies):
    """The calf's band (legs apart): yes; a band reaching the hands and the trunk: no (the measurer's blobs)."""
    tape = tape_of(bodies)
    body = StandingBody(bodies.vertices(2), bodies.faces, bodies.fractions)
    assert tape.legs_apart(body, body.at(0.12), body.at(0.28))
    assert not tape.legs_apart(body, body.at(0.4), body.at(0.6))
