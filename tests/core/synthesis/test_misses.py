"""What exact mode missed, as data (core.synthesis.misses): the five judged by the refinement's own criterion, the
extra measurements by 1 mm, nothing in IDW, and one line naming each miss."""

from ellimann_addon.core.synthesis.misses import MISS_CM, Miss, missed_text, request_misses
from ellimann_addon.core.synthesis.refine import EXACT_TOLERANCE

REQUEST = {"He": 160.0, "Sh": 40.0, "Br": 100.0, "Wa": 80.0, "Hi": 100.0}


def test_the_five_miss_beyond_the_refinements_tolerance_and_the_extra_ones_beyond_a_millimetre():
    just_in = 100.0 * (1.0 + 0.9 * EXACT_TOLERANCE)
    just_out = 100.0 * (1.0 + 1.1 * EXACT_TOLERANCE)
    measured = dict(REQUEST, Br=just_in, Hi=just_out, neck=35.0 + 0.9 * MISS_CM, thigh=55.0 - 1.1 * MISS_CM)
    missed = request_misses(measured, REQUEST, {"neck": 35.0, "thigh": 55.0})
    assert [m.key for m in missed] == ["Hi", "thigh"]
    assert missed[0] == Miss("Hi", just_out, 100.0) and missed[1].off_cm < -MISS_CM
    assert request_misses(measured, list(REQUEST.values()), {"neck": 35.0, "thigh": 55.0}) == missed  # 5 values too
    assert request_misses(measured, REQUEST, {"neck": 35.0, "thigh": 55.0}, mode="idw") == []


def test_one_line_names_each_miss_and_the_tolerances():
    line = missed_text([Miss("Sh", 32.81, 31.97), Miss("calf", 30.97, 82.0)])
    assert line.startswith("exact mode missed Sh by 2.63% (m_T 32.81 cm for 31.97 cm), calf by -51.03 cm")
    assert "(tolerance 0.001%, the extra measurements 1 mm;" in line
    assert "extra measurements" not in missed_text([Miss("Sh", 32.81, 31.97)])
