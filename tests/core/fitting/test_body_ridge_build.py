"""Sets from many bodies (issue 43): a build keeps a body space from ten bodies on (each measured), a bad bank
fails the build in one line, and bodies are added to a set already built without touching its RMs (slow: one body
fitted)."""

import shutil

import numpy as np
import pytest

from ellimann_addon.core.fitting.body_mesh import BodyMesh, read_obj
from ellimann_addon.core.fitting.reference_bodies import keep_space
from ellimann_addon.core.fitting.reference_build import ReferenceBuildError
from ellimann_addon.core.fitting.reference_extend import extend_reference_set
from ellimann_addon.core.synthesis.bodies import BodiesError, load_set_bodies, shipped_topology_labels
from ellimann_addon.core.synthesis.body_space import SPACE_MEASUREMENTS, load_set_body_space
from ellimann_addon.core.synthesis.manifest import MANIFEST_FILE, read_manifest
from ellimann_addon.core.synthesis.reference_set import load_reference_set
from ellimann_addon.core.synthesis.shipped import reference_folder
from tools.shipped.add_bodies import shipped_body_labels
from tools.shipped.add_body_space import bank
from tools.shipped.bodies import body_measurements, load_labels
from tools.shipped.reference_sets import BUILD_SETS, TRACING_FOLDER


@pytest.fixture(scope="module")
def meshes():
    """The first twelve bodies of the female bank as BodyMesh (with the refmodels' fingerprint) and their targets."""
    names, vertices, faces, joints = bank("female")
    traced = read_obj(BUILD_SETS["female"].refmodels / "average.obj", up="z")
    assert np.array_equal(traced.faces, faces)
    bodies = [BodyMesh(names[i], vertices[i], traced.faces, traced.edges_crc, joints[i]) for i in range(12)]
    labels = load_labels(TRACING_FOLDER)
    targets = {body.name: body_measurements(body, labels, BUILD_SETS["female"].fractions) for body in bodies}
    return bodies, targets


def test_a_build_keeps_a_body_space_from_ten_bodies_on(meshes):
    bodies, _ = meshes
    labels, fractions = shipped_body_labels(), BUILD_SETS["female"].fractions
    assert keep_space(bodies[:9], labels, fractions) is None
    told = []
    space = keep_space(bodies[:10], labels, fractions, lambda fraction, text: told.append(text))
    assert space.names == [body.name for body in bodies[:10]] and space.keys == SPACE_MEASUREMENTS
    assert len(told) == 10 and "10 of 10" in told[-1]
    # Bodies without joints (no skeleton.json beside them, as Build Reference Set always has them): regressed
    bare = [BodyMesh(body.name, body.vertices, body.faces, body.edges_crc, None) for body in bodies[:10]]
    regressed = keep_space(bare, shipped_topology_labels(bare[0].faces), fractions)  # as references build
    assert regressed.names == space.names
    own, guessed = space.mean[-72:], regressed.mean[-72:]  # the mean body's 24 joints, last in a flat body
    assert not np.array_equal(own, guessed) and np.allclose(own, guessed, atol=0.05)
    twice = bodies[:9] + [BodyMesh("again", bodies[4].vertices, bodies[4].faces, bodies[4].edges_crc, bodies[4].joints)]
    with pytest.raises(BodiesError, match="the same body twice"):
        keep_space(twice, labels, fractions)


def snapshot(folder):
    return {path.name: path.read_bytes() for path in sorted(folder.iterdir()) if path.is_file()}


@pytest.fixture
def small_set(tmp_path):
    folder = tmp_path / "female"
    shutil.copytree(reference_folder("female"), folder, ignore=shutil.ignore_patterns("*.blend", "*-fine", "male"))
    return folder


@pytest.mark.slow
def test_bodies_are_added_to_a_set_without_touching_its_rms(meshes, small_set):
    bodies, targets = meshes
    before = snapshot(small_set)
    told = []
    added = extend_reference_set(
        small_set, bodies[:1], targets, progress=lambda f, text: told.append(text), body_labels=shipped_body_labels()
    )
    assert snapshot(small_set) == before  # nothing written until asked
    added.write(small_set)
    after = snapshot(small_set)
    for name, content in before.items():
        if name not in (MANIFEST_FILE, "bodies.npz"):
            assert after[name] == content, name  # the RMs, the base and the body space as they were
    manifest = read_manifest(small_set)
    assert manifest.mannequins == [*read_manifest(reference_folder("female")).mannequins, bodies[0].name]
    assert manifest.targets_cm[bodies[0].name] == targets[bodies[0].name]
    assert load_set_bodies(small_set).names == manifest.mannequins[:6]
    assert load_set_body_space(small_set) is not None  # the shipped one, still named: six bodies make no new one
    reference = load_reference_set(small_set)
    rm = reference.mannequins[-1]
    measured = rm.measure()
    assert all(abs(measured[key] / targets[bodies[0].name][key] - 1.0) < 5e-3 for key in measured)
    assert told[0].startswith("fitting") and told[-1] == "added 1 bodies"


def test_adding_bad_bodies_is_refused_in_one_line_and_writes_nothing(meshes, small_set):
    bodies, targets = meshes
    before = snapshot(small_set)
    average = read_manifest(small_set).targets_cm["average"]
    clash = BodyMesh("average", bodies[0].vertices, bodies[0].faces, bodies[0].edges_crc, bodies[0].joints)
    cases = [
        ([clash], targets | {"average": average}, shipped_body_labels(), "already a mannequin"),
        (bodies[:1], {bodies[0].name: average}, shipped_body_labels(), "same targets"),
        (bodies[:1], targets, None, "labels"),
        ([], targets, shipped_body_labels(), "at least 1 bodies"),
    ]
    for new, wanted, labels, words in cases:
        with pytest.raises(ReferenceBuildError) as caught:
            extend_reference_set(small_set, new, wanted, body_labels=labels)
        assert "\n" not in str(caught.value) and words in str(caught.value), str(caught.value)
    assert snapshot(small_set) == before
