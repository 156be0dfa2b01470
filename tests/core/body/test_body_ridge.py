"""The ridge body model (core.body.ridge) over a body space (core.synthesis.body_space): it reproduces its own
bodies without regularisation when it can, cross-validation picks a finite lambda, the bank's mean request gives
the mean body, the bodies' weights reproduce the prediction, a tolerance lowers an input's say, the file reads back
within float16's rounding, and bad files and tolerances are refused in one line."""

import numpy as np
import pytest

from ellimann_addon.core.body.ridge import EXACT, LAMBDAS, RidgeBodyModel, product, resolve_tolerances, spd_inverse
from ellimann_addon.core.measurements import ALL_MEASUREMENTS, MEASUREMENTS
from ellimann_addon.core.synthesis.bodies import BodiesError, load_set_bodies
from ellimann_addon.core.synthesis.body_space import (
    SPACE_MEASUREMENTS,
    flat_bodies,
    load_set_body_space,
    read_body_space,
    space_from_arrays,
)
from ellimann_addon.core.synthesis.shipped import reference_folder


@pytest.fixture(scope="module")
def synthetic():
    """(vertices (12, V, 3), joints, measured (12, 21)): blends of the female set's five bodies, each on the floor,
    with made-up measurements (the regression is linear algebra: any numbers do)."""
    bodies = load_set_bodies(reference_folder("female"))
    rng = np.random.default_rng(5)
    mix = rng.uniform(-0.4, 0.8, (12, len(bodies)))
    vertices = bodies.mean + np.einsum("kn,nvc->kvc", mix, bodies.offsets.astype(float))
    joints = bodies.joints.mean(axis=0) + np.einsum("kn,njc->kjc", mix, bodies.joints - bodies.joints.mean(axis=0))
    measured = rng.uniform(20.0, 150.0, (12, len(SPACE_MEASUREMENTS)))
    return vertices, joints, measured, bodies.fractions


@pytest.fixture(scope="module")
def shipped():
    return {name: load_set_body_space(reference_folder(name)) for name in ("female", "male")}


def space_of(synthetic, count=12):
    vertices, joints, measured, fractions = synthetic
    return space_from_arrays(
        [f"b{i}" for i in range(count)], vertices[:count], joints[:count], measured[:count], fractions
    )


def test_without_regularisation_ridge_gives_its_own_bodies_back(synthetic):
    """Twelve bodies, twenty-one inputs: the regression can pass through every body, and does as lambda -> 0."""
    vertices, joints, measured, _ = synthetic
    model = RidgeBodyModel(space_of(synthetic), EXACT, lam=1e-9)
    flat = flat_bodies(vertices, joints)
    for i in range(len(vertices)):
        request = dict(zip(SPACE_MEASUREMENTS, measured[i]))
        found, found_joints = model.body(request)
        own, own_joints = model.space.split(flat[i])
        lift = own[:, 2].min()  # 0: each body is on its floor
        assert lift == 0.0
        assert np.abs(found - own).max() < 1e-6 and np.abs(found_joints - own_joints).max() < 1e-6
    # with regularisation it does not: the bodies are not where a smooth model would put them
    smooth = RidgeBodyModel(space_of(synthetic), EXACT, lam=1.0).body(dict(zip(SPACE_MEASUREMENTS, measured[0])))[0]
    assert np.abs(smooth - model.space.split(flat[0])[0]).max() > 1e-3


def test_cross_validation_picks_a_finite_lambda_no_worse_than_the_grid_ends(shipped):
    for name, space in shipped.items():
        for keys in (MEASUREMENTS, ALL_MEASUREMENTS, SPACE_MEASUREMENTS):
            found = RidgeBodyModel(space, EXACT).fit(keys)
            assert LAMBDAS[0] < found.lam < LAMBDAS[-1], (name, keys)
            for end in (LAMBDAS[0], LAMBDAS[-1]):
                assert found.cv_mm <= RidgeBodyModel(space, EXACT, lam=end).fit(keys).cv_mm + 1e-9, (name, end)


def test_a_request_at_the_banks_mean_gives_the_mean_body(shipped, synthetic):
    for space in (*shipped.values(), space_of(synthetic)):
        mean, mean_joints = space.split(space.mean.astype(float).copy())
        floor = mean[:, 2].min()
        for keys in (MEASUREMENTS, ALL_MEASUREMENTS, SPACE_MEASUREMENTS[:14]):
            request = {key: space.centre[space.keys.index(key)] for key in keys}
            for tolerances in (EXACT, None):
                vertices, joints = RidgeBodyModel(space, tolerances).body(request)
                assert np.abs(vertices - (mean - [0.0, 0.0, floor])).max() < 1e-9
                assert np.abs(joints - (mean_joints - [0.0, 0.0, floor])).max() < 1e-9


def test_the_bodies_weights_sum_to_one_and_give_the_prediction(synthetic):
    vertices, joints, measured, _ = synthetic
    space = space_of(synthetic)
    flat = flat_bodies(vertices, joints)
    model = RidgeBodyModel(space, None)
    request = {key: value + 3.0 for key, value in zip(SPACE_MEASUREMENTS[:8], measured[3])}
    weights = model.weights(request)
    assert abs(weights.sum() - 1.0) < 1e-12
    assert np.abs(weights @ flat - model.flat(request)).max() < 1e-9


def test_a_larger_tolerance_gives_an_input_less_say(shipped):
    space = shipped["female"]
    request = {key: space.centre[space.keys.index(key)] for key in ALL_MEASUREMENTS}
    moved = dict(request, thigh=request["thigh"] + 4.0)
    change = []
    for tolerance in (0.0, 0.5, 1.0, 2.0, 4.0):
        model = RidgeBodyModel(space, {"thigh": tolerance})
        change.append(np.abs(model.body(moved)[0] - model.body(request)[0]).max())
    assert all(a > b for a, b in zip(change, change[1:])), change
    assert np.array_equal(resolve_tolerances(EXACT, ("He", "neck")), [0.0, 0.0])
    assert np.array_equal(resolve_tolerances({"He": 0.2}, ("He", "neck")), [0.2, 0.9])  # neck: ISO's 9 mm


@pytest.mark.parametrize("bad", ["loose", {"He": -1.0}, {"Br": float("nan")}, {"Wa": "1 cm"}])
def test_bad_tolerances_are_refused_in_one_line(bad):
    with pytest.raises(ValueError) as caught:
        resolve_tolerances(bad, MEASUREMENTS)
    assert "\n" not in str(caught.value) and "tolerances" in str(caught.value)


def test_a_written_body_space_reads_back_within_float16s_rounding(synthetic, tmp_path):
    space = space_of(synthetic)
    again = read_body_space(space.save(tmp_path / "body_space.npz"))
    assert again.names == space.names and again.keys == space.keys
    request = dict(zip(SPACE_MEASUREMENTS[:11], synthetic[2][2] + 1.0))
    before, after = RidgeBodyModel(space).body(request)[0], RidgeBodyModel(again).body(request)[0]
    assert np.abs(before - after).max() < 1e-4  # 0.1 mm


def test_bad_body_space_files_are_refused_in_one_line(synthetic, tmp_path):
    space = space_of(synthetic)
    cases = {"not a zip": b"not a zip"}
    for key, value in (("format", np.array("other")), ("version", np.array(9)), ("gram", np.zeros((3, 3)))):
        data = dict(np.load(space.save(tmp_path / "good.npz")))
        data[key] = value
        np.savez(tmp_path / "case.npz", **data)
        cases[key] = (tmp_path / "case.npz").read_bytes()
    data = dict(np.load(tmp_path / "good.npz"))
    data["keys"] = np.array(["shoe size"] + list(data["keys"][1:]))
    np.savez(tmp_path / "case.npz", **data)
    cases["keys"] = (tmp_path / "case.npz").read_bytes()
    for what, content in cases.items():
        path = tmp_path / "bad.npz"
        path.write_bytes(content)
        with pytest.raises(BodiesError) as caught:
            read_body_space(path)
        assert "\n" not in str(caught.value) and str(path) in str(caught.value), what


def test_too_few_bodies_or_missing_measurements_make_no_space(synthetic):
    vertices, joints, measured, fractions = synthetic
    with pytest.raises(BodiesError, match="at least 10 bodies"):
        space_from_arrays(list("abcdefghi"), vertices[:9], joints[:9], measured[:9], fractions)
    holed = measured.copy()
    holed[2, 4] = np.nan
    with pytest.raises(BodiesError, match="finite"):
        space_from_arrays([f"b{i}" for i in range(12)], vertices, joints, holed, fractions)


def test_the_fits_own_products_and_inverse_are_numpys_within_rounding():
    """product and spd_inverse (numpy's loops, not BLAS's threads: the same bits with 1 or 2 threads) against @ and
    np.linalg.inv, on shapes the fit has."""
    rng = np.random.default_rng(3)
    for n in (1, 5, 21):
        a = rng.normal(size=(86, n))
        spd = a.T @ a + 1e-3 * np.eye(n)
        inverse = spd_inverse(spd)
        assert np.allclose(inverse, np.linalg.inv(spd), rtol=1e-9, atol=1e-12)
        assert np.allclose(product(spd, inverse), np.eye(n), atol=1e-9)
        v, w = rng.normal(size=n), rng.normal(size=86)
        assert np.allclose(product(a, v), a @ v) and np.allclose(product(w, a), w @ a)
        assert np.allclose(product(a.T, a), a.T @ a) and np.isclose(product(v, v), v @ v)
