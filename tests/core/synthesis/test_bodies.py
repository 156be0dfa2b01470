"""A reference set's bodies (core.synthesis.bodies): the shipped files read back, the tape reads the five as the
body-mesh measurer does to the last bit, bad bodies refused in one line, an old folder without bodies loads as
before, and the manifest without bodies is written as it always was; the shipped topology's labels known from its
triangles, joints regressed for bodies without them or read from a skeleton file."""

import json
import shutil

import numpy as np
import pytest

from ellimann_addon.core.body.tape import Tape
from ellimann_addon.core.measure.body import measure_body_mesh
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.bodies import (
    BodiesError,
    BodyLabels,
    from_meshes,
    load_set_bodies,
    makehuman_joint,
    read_bodies,
    shipped_topology_labels,
    skeleton_joints,
)
from ellimann_addon.core.synthesis.manifest import MANIFEST_FILE, read_manifest
from ellimann_addon.core.synthesis.reference_set import load_reference_set
from ellimann_addon.core.synthesis.shipped import reference_folder


@pytest.fixture(scope="module")
def female():
    return load_set_bodies(reference_folder("female"))


def test_the_shipped_sets_carry_five_bodies_of_one_topology_with_their_measurements():
    for name in ("female", "male", "female-fine", "male-fine"):
        folder = reference_folder(name)
        bodies = load_set_bodies(folder)
        assert bodies.names == read_manifest(folder).mannequins
        assert bodies.offsets.shape == (5, 13348, 3) and bodies.faces.shape == (26692, 3)
        assert np.allclose(bodies.joint_weight.sum(axis=1), 1.0)
        assert np.all(np.isfinite(bodies.measured[:, : len(MEASUREMENTS)]))


def test_every_bone_of_the_body_model_maps_on_a_joint():
    assert makehuman_joint("upperarm02.L") == "L_Shoulder" and makehuman_joint("finger1-2.R") == "R_Wrist"
    assert makehuman_joint("finger3-3.L") == "L_Hand" and makehuman_joint("spine04") == "Pelvis"
    assert makehuman_joint("neck03") == "Neck" and makehuman_joint("toe5-1.R") == "R_Foot"
    assert makehuman_joint("tail") is None
    assert makehuman_joint("L_Hip") == "L_Hip"  # weights already on the 24 joints (a shipped set's)


def test_the_tape_reads_the_five_as_the_body_mesh_measurer_to_the_last_bit(female):
    tape = Tape(female.faces, female.arms, female.fractions)
    for i in (0, 2, 4):
        vertices = female.vertices(i)
        full = measure_body_mesh(vertices, female.faces, female.fractions, arms=female.arms).values
        assert tape.five(vertices) == {key: full[key] for key in MEASUREMENTS}


def test_a_written_bodies_file_reads_back(female, tmp_path):
    path = female.save(tmp_path / "bodies.npz")
    again = read_bodies(path)
    assert again.names == female.names and np.array_equal(again.faces, female.faces)
    assert np.abs(again.offsets - female.offsets).max() == 0.0


def test_bad_bodies_are_refused_in_one_line(female, tmp_path):
    vertices = np.stack([female.vertices(i) for i in range(3)])
    labels = (female.region, list(female.region_names))
    bones = (female.joint_index, female.joint_weight, np.array(["root"] * 24))  # only for the shapes
    joints = female.joints[:3]
    cases = {
        "another topology": (vertices[:, :-10], female.faces[:100], joints),
        "lying": (vertices[:, :, [2, 1, 0]], female.faces, joints),
        "in centimetres": (vertices * 100.0, female.faces, joints),
        "facing +Y": (vertices * [-1.0, -1.0, 1.0], female.faces, joints * [-1.0, -1.0, 1.0]),
    }
    for what, (v, f, j) in cases.items():
        with pytest.raises(BodiesError) as caught:
            from_meshes(["a", "b", "c"], v, f, *labels, bones, j)
        assert "\n" not in str(caught.value), what
    broken = tmp_path / "bodies.npz"
    broken.write_bytes(b"not a zip")
    with pytest.raises(BodiesError, match="cannot be read"):
        read_bodies(broken)


def test_an_old_folder_without_bodies_loads_as_before(tmp_path):
    folder = tmp_path / "old"
    shutil.copytree(reference_folder("female"), folder, ignore=shutil.ignore_patterns("*.blend", "bodies.npz"))
    data = json.loads((folder / MANIFEST_FILE).read_text())
    del data["bodies"]
    (folder / MANIFEST_FILE).write_text(json.dumps(data))
    assert load_set_bodies(folder) is None
    assert len(load_reference_set(folder)) == 5
    assert "bodies" not in read_manifest(folder).to_dict()  # written as it always was
    data["bodies"] = "../elsewhere.npz"
    (folder / MANIFEST_FILE).write_text(json.dumps(data))
    with pytest.raises(Exception, match="bodies"):
        read_manifest(folder)


def test_the_shipped_topology_s_labels_are_known_from_its_triangles(female):
    """A body the shipped body model made (its triangles the shipped bodies') needs no labels file: its region
    labels and bone weights are the shipped sets', its joints regressed from its vertices."""
    labels = shipped_topology_labels(female.faces)
    assert np.array_equal(labels.region, female.region) and labels.region_names == female.region_names
    kept = from_meshes(
        ["a", "b"],
        np.stack([female.vertices(0), female.vertices(3)]),
        female.faces,
        labels.region,
        list(labels.region_names),
        labels.bones,
        np.stack([labels.regressor(female.vertices(0)), labels.regressor(female.vertices(3))]),
    )
    assert np.abs(kept.dense_weights - female.dense_weights).max() < 1e-12  # the same weights on the 24 joints
    assert shipped_topology_labels(female.faces[:, ::-1]) is None  # other triangles: no labels
    assert shipped_topology_labels(female.faces[:-1]) is None


def test_regressed_joints_follow_the_body(female):
    """The regressor fits the shipped bodies' joints (within a few millimetres) and moves with the body: a
    translated body's joints are translated alike (an affine combination of its vertices), a scaled body's scaled
    (about the origin)."""
    labels = shipped_topology_labels(female.faces)
    for i in range(len(female)):
        assert np.abs(labels.regressor(female.vertices(i)) - female.joints[i]).max() < 0.01
    body = female.vertices(4)
    shift = np.array([0.3, -0.2, 0.1])
    assert np.allclose(labels.regressor(body + shift), labels.regressor(body) + shift, atol=1e-6)
    assert np.allclose(labels.regressor(1.1 * body), 1.1 * labels.regressor(body), atol=1e-6)


def test_bodies_without_joints_are_kept_with_regressed_ones_or_refused_in_one_line(female):
    from ellimann_addon.core.fitting.body_mesh import BodyMesh
    from ellimann_addon.core.fitting.reference_bodies import keep_bodies

    meshes = [BodyMesh(name, female.vertices(i), female.faces) for i, name in enumerate(female.names)]
    labels = shipped_topology_labels(female.faces)
    kept = keep_bodies(meshes, labels, female.fractions)
    assert np.abs(kept.joints - female.joints).max() < 0.01
    assert np.allclose(kept.measured, female.measured, atol=0.02, equal_nan=True)
    bare = BodyLabels(labels.region, labels.region_names, labels.bones)
    with pytest.raises(BodiesError) as caught:  # the builder's ReferenceBuildError in one line
        keep_bodies(meshes, bare, female.fractions)
    assert "\n" not in str(caught.value) and "have no joints" in str(caught.value)


def test_a_skeleton_file_gives_each_body_its_joints(tmp_path, female):
    from tools.shipped.reference_sets import SHARED

    found = skeleton_joints(SHARED / "refmodels" / "skeleton.json")
    for i, name in enumerate(female.names):
        assert np.abs(found[name] - female.joints[i]).max() < 1e-6  # the joints the shipped bodies were kept with
    assert skeleton_joints(tmp_path / "none.json") == {}
    one = next(iter(json.loads((SHARED / "refmodels" / "skeleton.json").read_text())["bodies"].values()))
    flat = {bone: head[:2] for bone, head in one.items()}  # every bone head in 2-D: 24 points of 2
    broken = tmp_path / "skeleton.json"
    for text in ('{"bodies": {"a": {"root": [0, 0]}}}', '{"bodies": []}', json.dumps({"bodies": {"a": flat}})):
        broken.write_text(text, encoding="utf-8")
        with pytest.raises(BodiesError) as caught:
            skeleton_joints(broken)
        assert "\n" not in str(caught.value) and str(caught.value).startswith(str(broken))
