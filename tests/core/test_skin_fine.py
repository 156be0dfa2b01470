"""The skin on the fine topology (90 pieces): the same promises as on the 40 (tests/core/test_skin.py and
test_skinning.py), on the Average Reference Mannequin of each fine set."""

import numpy as np
import pytest

from devkit.mesh_checks import self_intersections, vertex_manifold
from ellimann_addon.core.drape.fit_metrics import mesh_distance
from ellimann_addon.core.geometry.ellipsoid import sample_surface
from ellimann_addon.core.geometry.mesh import euler_characteristic, is_closed_manifold, volume
from ellimann_addon.core.skin.settings import SkinSettings
from ellimann_addon.core.skin.surface import build_skin
from ellimann_addon.core.synthesis.shipped import FEMALE_FINE_SET, MALE_FINE_SET, named_reference_set
from tests.core.test_skin import MESHING_ERROR_M
from tests.core.test_skinning import VOLUME_TOLERANCE, every_frame, posed


@pytest.fixture(scope="module", params=[FEMALE_FINE_SET, MALE_FINE_SET])
def skin(request):
    mannequin = named_reference_set(request.param).mannequins[4]  # Average
    assert len(mannequin.topology) == 90
    return build_skin(mannequin, SkinSettings(10.0))


def test_the_fine_skin_is_one_closed_oriented_sphere_holding_every_piece(skin):
    m, vertices, faces = skin.mannequin, skin.vertices, skin.faces
    assert is_closed_manifold(faces) and vertex_manifold(faces, len(vertices))
    assert euler_characteristic(vertices, faces) == 2 and skin.volume > 0.0
    assert len(self_intersections(vertices, faces)) == 0
    points = np.concatenate([sample_surface(r, c, s, 100) for r, c, s in zip(m.rotation, m.center, m.semi_axes)])
    assert mesh_distance(points, vertices, faces)[0].max() <= MESHING_ERROR_M
    assert skin.pieces.max() < 90 and np.allclose(skin.weights.sum(axis=1), 1.0)


def test_the_fine_skin_keeps_its_volume_in_every_standard_pose_and_walk_frame(skin):
    bones, weights = skin.bones()
    changes = {
        name: volume(posed(skin, bones, weights, pose), skin.faces) / skin.volume - 1.0
        for name, pose in every_frame(skin.mannequin.joints)
    }
    worst = max(changes, key=lambda name: abs(changes[name]))
    assert abs(changes[worst]) <= VOLUME_TOLERANCE, (worst, changes[worst])
