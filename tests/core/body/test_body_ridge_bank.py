"""The shipped sets' body spaces (issue 43) and banks of bodies: the shipped sets name theirs and make their body
skins with the ridge by default (an old folder without one as before, with IDW), more exact inputs never give a
worse twin on average (leave-one-out over the bank), a body skin meets the five and reports what only informed
it, and a bad bank (another topology, lying, millimetres, the same body twice, an arm against the torso) is
refused in one line naming the body."""

import shutil
import statistics

import numpy as np
import pytest

from ellimann_addon.core.body.correct import BodySkinError
from ellimann_addon.core.body.model import IdwBodyModel
from ellimann_addon.core.body.ridge import EXACT, RidgeBodyModel
from ellimann_addon.core.body.skin import body_skin_maker
from ellimann_addon.core.measurements import ALL_MEASUREMENTS, MEASUREMENTS
from ellimann_addon.core.synthesis.bodies import BodiesError
from ellimann_addon.core.synthesis.body_space import (
    SPACE_FILE,
    SPACE_MEASUREMENTS,
    load_set_body_space,
    space_from_arrays,
    space_from_meshes,
)
from ellimann_addon.core.synthesis.manifest import MANIFEST_FILE, read_manifest
from ellimann_addon.core.synthesis.reference_set import load_reference_set
from ellimann_addon.core.synthesis.shipped import reference_folder
from tools.shipped.add_bodies import body_labels
from tools.shipped.add_body_space import training_bodies
from tools.shipped.reference_sets import BUILD_SETS


@pytest.fixture(scope="module")
def bank():
    names, vertices, faces, joints = training_bodies(BUILD_SETS["female"])
    return names, vertices, faces, joints, load_set_body_space(reference_folder("female"))


def test_the_shipped_sets_name_a_body_space_of_their_six_bodies_and_their_bank():
    for name in ("female", "male", "female-fine", "male-fine"):
        folder = reference_folder(name)
        space = load_set_body_space(folder)
        assert read_manifest(folder).body_space == SPACE_FILE
        assert len(space) == 86 and space.keys == SPACE_MEASUREMENTS and space.vertex_count == 13348
        assert space.names[:6] == [BUILD_SETS[name].reference_body, *read_manifest(folder).mannequins]
        assert space.fractions == read_manifest(folder).section_fractions
        assert np.all(np.isfinite(space.measured))


def test_the_shipped_sets_make_ridge_body_skins_and_old_folders_idw(tmp_path):
    reference = load_reference_set(reference_folder("female"))
    assert isinstance(body_skin_maker(reference).model, RidgeBodyModel)
    assert isinstance(body_skin_maker(reference, "idw").model, IdwBodyModel)
    old = tmp_path / "old"
    shutil.copytree(reference_folder("female"), old, ignore=shutil.ignore_patterns("*.blend", "female-fine", "male*"))
    manifest = (old / MANIFEST_FILE).read_text()
    (old / MANIFEST_FILE).write_text(manifest.replace(f'"body_space": "{SPACE_FILE}"', '"body_space": null'))
    (old / SPACE_FILE).unlink()
    old_set = load_reference_set(old)
    assert load_set_body_space(old) is None
    assert isinstance(body_skin_maker(old_set).model, IdwBodyModel)
    with pytest.raises(BodySkinError, match="no body space"):
        body_skin_maker(old_set, "ridge")
    with pytest.raises(BodySkinError, match="body model"):
        body_skin_maker(old_set, "nearest")
    # What IDW over the five bodies would not use is refused, not ignored
    idw = body_skin_maker(old_set)
    five = {key: float(idw.bodies.measured[0][i]) for i, key in enumerate(MEASUREMENTS)}
    refused = (({"tolerances": EXACT}, "tolerances need"), ({"shape": {"knee": 38.0}}, "shape measurements need"))
    for asks, said in refused:
        with pytest.raises(BodySkinError, match=said):
            idw.make(five, **asks)


def test_a_body_skin_meets_the_five_and_says_what_only_informed_it(bank):
    names, vertices, faces, joints, space = bank
    maker = body_skin_maker(load_reference_set(reference_folder("female")), tolerances=EXACT)
    truth = dict(zip(space.keys, space.measured[40]))
    five = {key: truth[key] for key in MEASUREMENTS}
    shape = {key: truth[key] for key in SPACE_MEASUREMENTS if key not in MEASUREMENTS}
    skin = maker.make(five, shape=shape)
    assert skin.misses() == [] and set(skin.request) == set(MEASUREMENTS)
    assert skin.informed == shape
    assert abs(skin.weights.sum() - 1.0) < 1e-9 and len(skin.weights) == len(space)
    with pytest.raises(BodySkinError, match="shoe"):
        maker.make(five, shape={"shoe": 40.0})
    for tolerances, said in (({"Hii": 1.0}, "Hii is no measurement"), ({"Hi": -1.0}, "0 or more"), ("loose", "loose")):
        with pytest.raises(BodySkinError, match=said):
            maker.make(five, tolerances=tolerances)


@pytest.mark.slow
def test_more_exact_inputs_never_give_a_worse_twin_on_average(bank):
    """Leave-one-out over every 6th of the bank's 86 bodies: the ridge's twin (before the correction) from the five,
    the eleven and all twenty-one, exact; and through a tape (1 cm on girths, 0.5 cm on lengths) the eleven with
    their tolerances still beat the five."""
    names, vertices, faces, joints, space = bank
    rng = np.random.default_rng(11)
    errors = {label: [] for label in ("five", "eleven", "all", "five noisy", "eleven noisy")}
    for i in range(0, len(names), 6):
        keep = [k for k in range(len(names)) if k != i]
        held = space_from_arrays([names[k] for k in keep], vertices[keep], joints[keep], space.measured[keep], {
            k: v for k, v in space.fractions.items()
        })  # fmt: skip
        truth = dict(zip(space.keys, space.measured[i]))
        body = vertices[i] - [0.0, 0.0, vertices[i][:, 2].min()]
        noise = {key: rng.standard_normal() * (1.0 if key in ("Br", "Wa", "Hi", "neck", "upper_arm", "thigh") else 0.5)
                 for key in ALL_MEASUREMENTS}  # fmt: skip
        for label, keys, tolerances, tape in (
            ("five", MEASUREMENTS, EXACT, {}),
            ("eleven", ALL_MEASUREMENTS, EXACT, {}),
            ("all", SPACE_MEASUREMENTS, EXACT, {}),
            ("five noisy", MEASUREMENTS, None, noise),
            ("eleven noisy", ALL_MEASUREMENTS, None, noise),
        ):
            request = {key: truth[key] + tape.get(key, 0.0) for key in keys}
            twin = RidgeBodyModel(held, tolerances).body(request)[0]
            errors[label].append(np.linalg.norm(twin - body, axis=1).mean())
    mean = {label: statistics.mean(values) for label, values in errors.items()}
    assert mean["five"] > mean["eleven"] > mean["all"], mean
    assert mean["five noisy"] > mean["eleven noisy"], mean


def bad_bank(bank, what):
    names, vertices, faces, joints, _ = bank
    vertices, joints, names = vertices[:10].copy(), joints[:10].copy(), list(names[:10])
    region, region_names, _ = body_labels()
    if what == "another topology":
        return names, vertices[:, :-6], faces[:-20], region, region_names, joints
    if what == "lying":
        vertices[3] = vertices[3][:, [0, 2, 1]]
    elif what == "millimetres":
        vertices[3] *= 1000.0
    elif what == "the same body twice":
        vertices[7] = vertices[2] + 1e-4
    elif what == "arms against the torso":
        arm = {side: np.isin(region, [region_names.index(f"{p}_{side}") for p in ("upper_arm", "forearm", "hand")])
               for side in "LR"}  # fmt: skip
        vertices[3][arm["L"], 0] -= 0.08
        vertices[3][arm["R"], 0] += 0.08
    return names, vertices, faces, region, region_names, joints


@pytest.mark.parametrize(
    "what, said",
    [
        ("another topology", "another topology"),
        ("lying", "lies down"),
        ("millimetres", "not a person's height"),
        ("the same body twice", "the same body twice"),
        ("arms against the torso", "touches the torso"),
    ],
)
def test_a_bad_bank_is_refused_in_one_line_naming_the_body(bank, what, said):
    names, vertices, faces, region, region_names, joints = bad_bank(bank, what)
    measured = []
    with pytest.raises(BodiesError) as caught:
        space_from_meshes(names, vertices, faces, region, region_names, joints, BUILD_SETS["female"].fractions,
                          progress=lambda done, total, name: measured.append(name))  # fmt: skip
    message = str(caught.value)
    assert "\n" not in message and said in message, message
    if what != "another topology":
        assert names[3] in message or names[7] in message, message
    assert measured == []  # refused before any body was measured
