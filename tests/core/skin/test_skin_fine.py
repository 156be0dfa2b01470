"""The skin on the fine topology (90 pieces) keeps its volume when posed, as on the 40
(tests/core/skin/test_skinning.py), on the Average Reference Mannequin of each fine set; tests/core/skin/test_skin.py
holds every Reference Mannequin of every shipped set, the fine ones too, to one closed oriented sphere holding every
piece."""

import pytest

from ellimann_addon.core.geometry.mesh import volume
from ellimann_addon.core.mannequin.skin_record import SkinSettings
from ellimann_addon.core.skin.surface import build_skin
from ellimann_addon.core.synthesis.shipped import FEMALE_FINE_SET, MALE_FINE_SET, named_reference_set
from tests.core.skin.test_skinning import VOLUME_TOLERANCE, every_frame, posed


@pytest.fixture(scope="module", params=[FEMALE_FINE_SET, MALE_FINE_SET])
def skin(request):
    mannequin = named_reference_set(request.param).mannequins[4]  # Average
    assert len(mannequin.topology) == 90
    return build_skin(mannequin, SkinSettings(10.0))


def test_the_fine_skin_keeps_its_volume_in_every_standard_pose_and_walk_frame(skin):
    bones, weights = skin.bones()
    changes = {
        name: volume(posed(skin, bones, weights, pose), skin.faces) / skin.volume - 1.0
        for name, pose in every_frame(skin.mannequin.joints)
    }
    worst = max(changes, key=lambda name: abs(changes[name]))
    assert abs(changes[worst]) <= VOLUME_TOLERANCE, (worst, changes[worst])
