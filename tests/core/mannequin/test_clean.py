import numpy as np
import pytest

from devkit.toy import rotation_from_vector
from ellimann_addon.core.geometry.ellipsoid import axis_extent, shape_matrix
from ellimann_addon.core.geometry.frames import SIGNED_PERMUTATIONS, axis_agreement, is_rotation
from ellimann_addon.core.mannequin import clean


def disturbed(toy, seed):
    rng = np.random.default_rng(seed)
    out = toy.copy()
    out.center += rng.normal(size=3) * 0.3 + rng.normal(size=out.center.shape) * 0.005
    out.rotation = np.stack([rotation_from_vector(rng.normal(size=3) * 0.05) @ r for r in out.rotation])
    q = SIGNED_PERMUTATIONS[rng.integers(0, 24, len(out.rotation))]
    out.rotation = out.rotation @ q
    out.semi_axes = np.einsum("nij,ni->nj", np.abs(q), out.semi_axes) * rng.uniform(0.95, 1.05, out.semi_axes.shape)
    return out


def test_register_puts_feet_on_the_floor_and_shoulders_on_the_axis(toy):
    m = clean.register_to_world(disturbed(toy, 1))
    lowest = np.min(m.center[:, 2] - axis_extent(m.rotation, m.semi_axes, 2))
    assert lowest == pytest.approx(0.0, abs=1e-12)
    idx = clean.landmark_indices(m.topology)
    assert np.allclose(m.center[idx, :2].mean(axis=0), 0.0, atol=1e-12)


def test_symmetrize_makes_the_body_symmetric_and_right_handed(toy):
    m = disturbed(toy, 2)
    assert clean.asymmetry(m) > 1e-3
    s = clean.symmetrize(m)
    assert clean.asymmetry(s) < 1e-12
    assert np.all(is_rotation(s.rotation))
    left = s.topology.indices("L")
    assert np.array_equal(s.rotation[left], m.rotation[left])


def test_clean_gives_consistent_labels_and_keeps_each_ellipsoid(toy):
    ms = [disturbed(toy, s) for s in range(5)]
    cleaned = clean.clean(ms, reference_index=0)
    for before, after in zip(ms, cleaned):
        assert clean.asymmetry(after) < 1e-12
        left = after.topology.indices("L")
        # the left side is only moved (registration) and relabelled, not reshaped
        assert np.allclose(
            shape_matrix(after.rotation[left], after.semi_axes[left]),
            shape_matrix(before.rotation[left], before.semi_axes[left]),
            atol=1e-12,
        )
        assert axis_agreement(after.rotation, cleaned[0].rotation).min() > 0.95


def test_missing_landmarks_are_reported(toy):
    from ellimann_addon.core.errors import MannequinError

    with pytest.raises(MannequinError, match="no 'Deltoid' ellipsoids"):
        clean.register_to_world(toy, label="Deltoid")


def test_clean_registers_after_mirroring(toy):
    """An asymmetric input whose right foot is lowest: mirroring the left lifts the body off the floor."""
    m = disturbed(toy, 3)
    right_shin = m.topology.index["6.b Shin.R"]
    m.center[right_shin, 2] -= 0.05
    cleaned = clean.clean([m])[0]
    lowest = np.min(cleaned.center[:, 2] - axis_extent(cleaned.rotation, cleaned.semi_axes, 2))
    assert lowest == pytest.approx(0.0, abs=1e-12)
    idx = clean.landmark_indices(cleaned.topology)
    assert np.allclose(cleaned.center[idx, :2].mean(axis=0), 0.0, atol=1e-12)
