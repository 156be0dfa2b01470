"""Joints belong to the mannequin: the JSON section (old files load), checks against the topology, the shipped
mannequins' joints, synthesis (exact at the Reference Mannequins) and deformations that move them with the
pieces."""

import json

import numpy as np
import pytest

from ellimann_addon.core.errors import MannequinError
from ellimann_addon.core.mannequin import skeleton
from ellimann_addon.core.mannequin.clean import register_to_world, symmetrize
from ellimann_addon.core.mannequin.joints import anchor_indices, follow_pieces, joints_from_dict
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.synthesis.idw import idw_weights, interpolate, interpolate_joints
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER, REFERENCE_NAMES, load_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize, synthesize_batch

STEMS = ("base_mannequin",) + REFERENCE_NAMES


@pytest.fixture(scope="module")
def reference():
    return load_reference_set()


@pytest.fixture(scope="module")
def average():
    return Mannequin.load(REFERENCE_FOLDER / "average.json")


def test_every_shipped_mannequin_has_symmetric_joints_near_its_body_landmarks():
    # Landmarks of the average body (refmodels/README.md, "Skeleton"): joint height / He.
    landmarks = {
        "L_Hip": 0.515,
        "L_Knee": 0.292,
        "L_Ankle": 0.050,
        "L_Shoulder": 0.792,
        "L_Elbow": 0.666,
        "L_Wrist": 0.564,
    }
    for stem in STEMS:
        m = Mannequin.load(REFERENCE_FOLDER / f"{stem}.json")
        assert m.joints is not None and m.joints.shape == (24, 3) and m.problems() == []
        mirrored = m.joints[skeleton.JOINT_TWINS] * [-1.0, 1.0, 1.0]
        assert np.abs(m.joints - mirrored).max() < 1e-12, stem
        if stem == "average":
            he = m.measure()["He"] / 100.0
            for name, fraction in landmarks.items():
                assert abs(m.joints[skeleton.JOINT_INDEX[name], 2] / he - fraction) < 0.01, name


def test_joints_json_round_trip_and_old_files_load(tmp_path, average):
    path = tmp_path / "a.json"
    average.save(path)
    data = json.loads(path.read_text())
    assert data["joints"]["names"] == list(skeleton.JOINT_NAMES) and data["joints"]["version"] == 1
    assert np.array_equal(Mannequin.load(path).joints, average.joints)
    del data["joints"]
    path.write_text(json.dumps(data))
    old = Mannequin.load(path)
    assert old.joints is None and "joints" not in old.to_dict()


@pytest.mark.parametrize(
    "change, words",
    [
        (lambda j: dict(j, version=2), ["joints.version", "2"]),
        (lambda j: dict(j, names=j["names"][::-1]), ["joints.names", "SMPL"]),
        (lambda j: dict(j, positions=j["positions"][:5]), ["joints.positions", "24x3"]),
        (lambda j: dict(j, positions=[[0, 0, "a"]] * 24), ["joints.positions"]),
        (lambda j: "joints", ["joints", "object"]),
    ],
)
def test_a_bad_joints_section_is_refused_naming_the_field(average, change, words):
    data = average.to_dict()
    data["joints"] = change(data["joints"])
    with pytest.raises(MannequinError) as error:
        Mannequin.from_dict(data)
    assert all(w in str(error.value) for w in words) and "\n" not in str(error.value)


def test_joints_of_another_mannequin_do_not_match_its_topology(average):
    tall = Mannequin.load(REFERENCE_FOLDER / "tall_chubby.json")
    small = Mannequin.load(REFERENCE_FOLDER / "small_slim.json")
    with pytest.raises(MannequinError, match="joints: .* is not where the pieces of its bones are"):
        tall.copy(joints=small.joints).check()
    moved = average.copy(joints=average.joints + [0.0, 0.0, 0.2])
    assert any(p.field == "joints" for p in moved.problems())
    shuffled = average.joints.copy()
    shuffled[[skeleton.JOINT_INDEX["L_Wrist"], skeleton.JOINT_INDEX["L_Ankle"]]] = shuffled[
        [skeleton.JOINT_INDEX["L_Ankle"], skeleton.JOINT_INDEX["L_Wrist"]]
    ]
    assert any("L_Wrist" in p.message for p in average.copy(joints=shuffled).problems())


def test_a_topology_whose_parts_have_no_bone_cannot_carry_joints(average):
    data = average.to_dict()
    data["ellipsoids"][0]["name"] = "1.a Antenna"
    data["ellipsoids"][1]["partner"] = "1.a Antenna"
    with pytest.raises(MannequinError, match="'1.a Antenna' bone: has no bone"):
        Mannequin.from_dict(data)
    del data["joints"]
    assert Mannequin.from_dict(data).joints is None  # without joints it is a valid mannequin


def test_every_part_has_a_bone_and_cushions_cross_exactly_four_kinds_of_joint(average):
    bones = skeleton.bone_names(average.topology)
    assert set(bones) == set(average.topology.names)
    crossing = {
        (average.topology.names[i], skeleton.JOINT_NAMES[j]) for i, _, j in skeleton.cross_joint_pairs(average.topology)
    }
    assert crossing == {
        (f"{p}.{s}", f"{s}_{j}")
        for s in "LR"
        for p, j in (("3.a Upper Arm", "Elbow"), ("4.a Hand", "Hand"), ("7.a Foot", "Foot"))
    } | {(f"12.a Oblique.{s}", "Spine1") for s in "LR"}


@pytest.mark.parametrize("mode", ["exact", "idw"])
@pytest.mark.parametrize("normalize", ["proportional", "none"])
def test_synthesized_joints_at_a_reference_mannequins_measurements_are_its_joints(reference, mode, normalize):
    result = synthesize_batch(reference, reference.measurements, mode=mode, normalize=normalize)
    assert np.abs(result.joints - reference.joints).max() < 1e-12
    for i, rm in enumerate(reference.mannequins):
        assert np.abs(result.mannequin(i).joints - rm.joints).max() < 1e-12


def test_synthesized_joints_are_symmetric_valid_and_between_the_references(reference):
    mannequin, _, _ = synthesize(reference, [165, 41.5, 101.25, 82.75, 117.5])
    assert mannequin.problems() == []
    assert np.abs(mannequin.joints - mannequin.joints[skeleton.JOINT_TWINS] * [-1, 1, 1]).max() < 1e-12
    heights = reference.joints[..., 2]
    assert np.all(mannequin.joints[:, 2] > heights.min(axis=0) - 0.02)
    assert np.all(mannequin.joints[:, 2] < heights.max(axis=0) * 165 / 171 + 0.05)


def test_a_request_alone_gets_the_joints_it_gets_in_a_batch(reference):
    requests = np.array([[165, 41.5, 101.25, 82.75, 117.5], [150, 35, 90, 70, 95], [170, 50, 140, 130, 140]])
    batch = synthesize_batch(reference, requests)
    for i, request in enumerate(requests):
        assert np.array_equal(synthesize_batch(reference, [request]).joints[0], batch.joints[i])


@pytest.mark.parametrize(
    "metric, power, normalize",
    [("raw", 2.0, "proportional"), ("normalized", 1.0, "none"), ("normalized", 4.0, "height")],
)
def test_a_batch_shares_its_idw_weights_with_the_same_results_as_each_part_alone(reference, metric, power, normalize):
    requests = np.array([[165, 41.5, 101.25, 82.75, 117.5], [150, 35, 90, 70, 95], [170, 50, 140, 130, 140]])
    batch = synthesize_batch(reference, requests, mode="idw", metric=metric, power=power, normalize=normalize)
    alone = interpolate_joints(reference, requests, metric, power, normalize)
    assert np.array_equal(batch.joints, alone)
    weights = idw_weights(reference, requests, metric, power)
    assert np.array_equal(interpolate_joints(reference, requests, metric, power, normalize, weights), alone)
    pieces = interpolate(reference, requests, metric, power, normalize)
    for field, value in zip(("rotation", "center", "semi_axes"), pieces):
        assert np.array_equal(getattr(batch, field), value)
    for shared, value in zip(interpolate(reference, requests, metric, power, normalize, weights), pieces):
        assert np.array_equal(shared, value)


def test_a_deformation_carries_each_joint_with_its_anchor_piece(average):
    anchors = anchor_indices(average.topology)
    before = (average.rotation, average.center, average.semi_axes)
    # A rigid motion of every piece moves the joints by that motion exactly.
    angle = 0.3
    turn = np.array([[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    shift = np.array([0.1, -0.2, 0.05])
    after = (turn @ average.rotation, average.center @ turn.T + shift, average.semi_axes)
    assert np.allclose(
        follow_pieces(average.joints, anchors, before, after), average.joints @ turn.T + shift, atol=1e-12
    )
    # Scaling every piece about the floor by s scales the joints the same way.
    after = (average.rotation, average.center * 1.1, average.semi_axes * 1.1)
    assert np.allclose(follow_pieces(average.joints, anchors, before, after), average.joints * 1.1, atol=1e-12)


def test_cleaning_moves_and_mirrors_the_joints_with_the_pieces(average):
    moved = average.translated([0.2, 0.1, 0.3])
    assert np.allclose(moved.joints - average.joints, [0.2, 0.1, 0.3])
    back = register_to_world(moved)
    assert np.allclose(back.joints, average.joints, atol=1e-12)
    lopsided = average.joints.copy()
    lopsided[skeleton.JOINT_INDEX["R_Knee"]] += [0.01, 0.0, 0.0]
    assert np.allclose(symmetrize(average.copy(joints=lopsided)).joints, average.joints, atol=1e-12)
    assert joints_from_dict(None) is None
