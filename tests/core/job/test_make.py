"""core.job: one request made into a mannequin and its skin. The skin's kind is decided by the job: the body skin
(core.body) where the set has bodies, the skin over the pieces elsewhere, or where no body skin meets the request
("auto": with a warning saying why); a kind asked that cannot be made is refused before any work."""

import numpy as np
import pytest

from devkit import synthetic
from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.job.make import make
from ellimann_addon.core.job.request import Request, check
from ellimann_addon.core.mannequin.skin_record import SkinSettings
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.misses import SKIN_MISS_CM
from ellimann_addon.core.synthesis.reference_set import load_reference_set
from ellimann_addon.core.synthesis.shipped import named_reference_set

FIVE = dict(zip(MEASUREMENTS, (165.0, 41.5, 101.25, 82.75, 117.5)))


@pytest.fixture(scope="module")
def female():
    return named_reference_set("female")


def test_auto_makes_the_body_skin_where_the_set_has_bodies_and_it_meets_the_request(female):
    job = check(Request(FIVE, female, {"neck": 33.0}, skin=SkinSettings(kind="auto")))
    assert job.skin.kind == "body"
    result = make(job)
    skin = result.skin.skin
    assert result.skin.exact and not result.missed and skin.settings.kind == "body"
    for key, wanted in {**FIVE, "neck": 33.0}.items():
        assert abs(result.skin.measured[key] - wanted) <= SKIN_MISS_CM, key
    assert result.measured["Br"] == pytest.approx(FIVE["Br"], rel=1e-5)  # the pieces still meet it by m_T
    np.testing.assert_array_equal(result.mannequin.joints, skin.joints)  # one skeleton: the pieces bend with it
    record = skin.record()
    assert record["version"] == 2 and record["request"] == {**FIVE, "neck": 33.0}


def test_a_body_skin_is_made_again_from_its_record_the_same(female):
    first = make(check(Request(FIVE, female, skin=SkinSettings(kind="body"))))
    pieces = first.mannequin.copy(skin=first.skin.skin.record())
    again = make(check(Request(mannequin=pieces, skin=SkinSettings(kind="auto"))))  # the record says which
    assert again.skin.skin.settings.kind == "body"
    np.testing.assert_array_equal(again.skin.skin.vertices, first.skin.skin.vertices)


def test_a_request_no_body_skin_meets_gets_the_pieces_skin_when_auto_and_is_refused_when_body(female):
    beyond = {**FIVE, "Br": 150.0, "Wa": 64.0}  # a bust twice the waist: no body of the set's has such proportions
    result = make(check(Request(beyond, female, skin=SkinSettings(10.0, kind="auto"))))
    assert result.skin.skin.settings.kind == "pieces"
    assert any("skin is made over the pieces instead" in warning for warning in result.warnings)
    with pytest.raises(ElliMannError, match="Br|Wa"):
        make(check(Request(beyond, female, skin=SkinSettings(kind="body"))))


def test_a_set_without_bodies_gets_the_pieces_skin_and_refuses_a_body_skin_before_any_work(tmp_path):
    reference = load_reference_set(synthetic.write_reference_folder(tmp_path))
    request = {key: float(np.mean(reference.measurements[:, i])) for i, key in enumerate(MEASUREMENTS)}
    assert check(Request(request, reference, skin=SkinSettings(10.0, kind="auto"))).skin.kind == "pieces"
    with pytest.raises(ElliMannError, match="skin_kind: the .* set has no bodies"):
        check(Request(request, reference, skin=SkinSettings(kind="body")))
