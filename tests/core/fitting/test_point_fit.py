import numpy as np
import pytest

from devkit.toy import rotation_from_vector
from ellimann_addon.core.fitting import point_fit as fit
from ellimann_addon.core.geometry import mesh
from ellimann_addon.core.geometry.frames import is_rotation


def surface(rotation, center, semi, subdivisions=3):
    v, _ = mesh.icosphere(subdivisions)
    return (v * semi) @ rotation.T + center


@pytest.mark.parametrize("mode", fit.FIT_MODES)
def test_fit_recovers_an_ellipsoid_from_its_surface(mode):
    r = rotation_from_vector((0.3, -0.5, 0.9))
    pts = surface(r, (0.1, -0.2, 1.2), (0.05, 0.12, 0.2))
    rot, c, d = fit.fit_ellipsoid(pts, mode)
    assert is_rotation(rot)
    assert np.allclose(c, (0.1, -0.2, 1.2))
    assert np.allclose(np.sort(d), (0.05, 0.12, 0.2), rtol=1e-9)


def test_inscribed_inside_enclosing_outside_noisy_points():
    rng = np.random.default_rng(0)
    pts = surface(np.eye(3), np.zeros(3), (0.1, 0.15, 0.3)) * rng.uniform(0.9, 1.1, (642, 1))
    for mode, inside in (("inscribed", False), ("enclosing", True)):
        rot, c, d = fit.fit_ellipsoid(pts, mode)
        r2 = np.sum(((pts - c) @ rot / d) ** 2, axis=1)
        assert np.all(r2 <= 1 + 1e-9) if inside else np.all(r2 >= 1 - 1e-9)


def test_fit_labels_axes_to_agree_with_the_world():
    r, _, _ = fit.fit_ellipsoid(surface(np.eye(3), np.zeros(3), (0.3, 0.1, 0.2)))
    assert np.allclose(r, np.eye(3), atol=1e-9)


def test_fit_refuses_bad_input():
    with pytest.raises(ValueError, match="at least 4"):
        fit.fit_ellipsoid(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="coplanar"):
        fit.fit_ellipsoid(np.column_stack([np.random.rand(10, 2), np.zeros(10)]))
    with pytest.raises(ValueError, match="NaN"):
        fit.fit_ellipsoid(np.full((5, 3), np.nan))
    with pytest.raises(ValueError, match="mode"):
        fit.fit_ellipsoid(np.random.rand(10, 3), "best")


def test_fit_affine_recovers_an_applied_transform():
    unit, _ = mesh.icosphere(2)
    affine = np.eye(4)
    affine[:3, :3] = rotation_from_vector((0.1, 0.7, -0.3)) @ np.diag((0.1, 0.2, 0.05))
    affine[:3, 3] = (0.3, -0.1, 1.0)
    matrix, residual = fit.fit_affine(unit, unit @ affine[:3, :3].T + affine[:3, 3])
    assert np.allclose(matrix, affine, atol=1e-12) and residual < 1e-12
    edited = unit.copy()
    edited[0] *= 1.5
    assert fit.fit_affine(unit, edited)[1] > 0.05
    with pytest.raises(ValueError, match="corresponding points"):
        fit.fit_affine(unit, unit[:-1])


def test_inscribed_fit_keeps_the_unselected_rest_of_the_surface_outside():
    # A sphere with a groove pressed into one side; the selection is everything but the groove, so
    # its ellipsoid, sized on the selection alone, reaches through the groove out of the body.
    body = surface(np.eye(3), np.zeros(3), (0.2, 0.2, 0.2), subdivisions=4)
    groove = (np.abs(body[:, 2]) < 0.05) & (body[:, 0] < -0.1)
    body[groove] *= 0.5

    def inside(fitted, points):
        rotation, center, semi = fitted
        return np.sum(((points - center) @ rotation / semi) ** 2, axis=1) < 1 - 1e-9

    alone = fit.fit_ellipsoid(body[~groove], "inscribed")
    assert inside(alone, body[groove]).any()
    fitted = fit.fit_ellipsoid(body[~groove], "inscribed", surface=body[groove])
    assert not inside(fitted, body).any()
    assert np.allclose(fitted[0], alone[0]) and np.allclose(fitted[1], alone[1])  # same axes, only smaller
    assert np.all(fitted[2] < alone[2])
    for mode in ("moments", "enclosing"):  # the surface only bounds the inscribed size
        assert np.array_equal(
            fit.fit_ellipsoid(body[~groove], mode, surface=body[groove])[2], fit.fit_ellipsoid(body[~groove], mode)[2]
        )
    with pytest.raises(ValueError, match="surface"):
        fit.fit_ellipsoid(body[~groove], "inscribed", surface=np.full((2, 3), np.nan))
