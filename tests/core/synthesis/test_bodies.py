"""A reference set's bodies (core.synthesis.bodies): the shipped files read back, the tape reads the five as the
body-mesh measurer does to the last bit, bad bodies refused in one line, an old folder without bodies loads as
before, and the manifest without bodies is written as it always was."""

import json
import shutil

import numpy as np
import pytest

from ellimann_addon.core.body.tape import Tape
from ellimann_addon.core.measure.body import measure_body_mesh
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.bodies import (
    BodiesError,
    from_meshes,
    load_set_bodies,
    makehuman_joint,
    read_bodies,
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
