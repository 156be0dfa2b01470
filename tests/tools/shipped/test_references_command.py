"""``ellimann references build`` on three of the reference bodies, exported as Blender writes OBJ (Y up): its
RMs are the shipped ones (an RM depends only on its body, and the Average, nearest the three's mean, labels them
as it labels the shipped five), ``references check`` passes, the set synthesizes and measures exactly, and it keeps
the bodies for their body skin."""

import json

import numpy as np
import pytest

from devkit.cli_runs import assert_one_line_error, run
from ellimann_addon.core.constants import REFERENCE_MEASUREMENTS
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry.mesh import from_scene_axes
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.bodies import load_set_bodies
from ellimann_addon.core.synthesis.manifest import read_manifest
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER, load_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize_batch
from tools.shipped.build_reference import CHECK_TOLERANCE, DEFAULT_REFMODELS

THREE = ("small_slim", "tall_chubby", "average")


def _targets_csv(folder):
    path = folder / "targets.csv"
    path.write_text(
        "name,"
        + ",".join(MEASUREMENTS)
        + "\n"
        + "".join(
            f"{name}," + ",".join(f"{REFERENCE_MEASUREMENTS[name][k]:g}" for k in MEASUREMENTS) + "\n"
            for name in REFERENCE_MEASUREMENTS
        )
    )
    return path


def _as_blender_exports(body, path):
    """``body`` written as Blender exports OBJ (Y up, -Z forward), the axes ``references build`` reads by default."""
    path.write_text(
        "".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in from_scene_axes(body.vertices))
        + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in body.faces)
    )
    return str(path)


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The three bodies as Blender exports them (Y up): the RMs must be those the shipped set built from the same
    bodies in ElliMann's Z-up axes."""
    folder = tmp_path_factory.mktemp("three")
    exported = [
        _as_blender_exports(read_obj(DEFAULT_REFMODELS / f"{n}.obj", up="z"), folder / f"{n}.obj") for n in THREE
    ]
    args = [
        "references",
        "build",
        "--base",
        str(REFERENCE_FOLDER / "base_mannequin.json"),
        "--targets",
        str(_targets_csv(folder)),
        "--bodies",
        *exported,
        "-o",
        str(folder / "set"),
        "--workers",
        "2",
        "--name",
        "three",
    ]
    from ellimann_addon import cli

    assert cli.main(args) == 0
    return folder / "set"


@pytest.mark.slow
def test_the_rms_are_the_shipped_ones(built):
    for name in THREE:
        fresh, shipped = Mannequin.load(built / f"{name}.json"), Mannequin.load(REFERENCE_FOLDER / f"{name}.json")
        for attr in ("rotation", "center", "semi_axes"):
            assert np.abs(getattr(fresh, attr) - getattr(shipped, attr)).max() <= CHECK_TOLERANCE, (name, attr)


@pytest.mark.slow
def test_check_passes_and_the_set_synthesizes_exactly(built, capsys):
    code, out, err = run(["references", "check", str(built)], capsys)
    assert code == 0, err
    assert "'three', 3 RMs, manifest reference_set.json" in out
    reference = load_reference_set(built)
    assert reference.names == list(THREE)
    # IDW is exact at the set's own RMs; exact mode meets requests between and beyond them
    own = synthesize_batch(reference, reference.measurements, mode="idw")
    assert np.allclose(own.center, reference.center, atol=1e-12)
    requests = np.array([reference.measurements.mean(axis=0), [153.75, 35.75, 101.25, 102.5, 134.75]])
    batch = synthesize_batch(reference, requests, mode="exact")
    assert batch.converged.all()
    assert np.allclose(batch.measured, requests, rtol=1e-5)


@pytest.mark.slow
def test_the_set_keeps_its_bodies_and_makes_their_body_skin(built, tmp_path, capsys):
    """The bodies are the body model's: kept (bodies.npz), their joints regressed from the labels (no skeleton
    file beside them), and the set's --skin is their body skin, exact on the tape."""
    bodies, shipped = load_set_bodies(built), load_set_bodies(REFERENCE_FOLDER)
    assert bodies.names == list(THREE) and read_manifest(built).body_space is None  # a space from ten bodies on
    for i, name in enumerate(THREE):
        j = shipped.names.index(name)
        assert np.abs(bodies.vertices(i) - shipped.vertices(j)).max() < 1e-3
        assert np.abs(bodies.joints[i] - shipped.joints[j]).max() < 0.03
    asked = ["--he", "160", "--sh", "40", "--br", "100", "--wa", "85", "--hi", "105"]
    out = tmp_path / "x.json"
    code, stdout, err = run(["synth", "--references", str(built), *asked, "--skin", "-o", str(out), "--json"], capsys)
    skin = json.loads(stdout)["skin"]
    assert code == 0 and skin["kind"] == "body", err
    for key, value in zip(MEASUREMENTS, map(float, asked[1::2])):
        assert abs(skin["measured"][key] - value) <= 0.1, key


def test_a_body_with_shuffled_vertex_order_is_refused(tmp_path, capsys):
    body = read_obj(DEFAULT_REFMODELS / "average.obj", up="z")
    order = np.random.default_rng(0).permutation(len(body.vertices))
    inverse = np.argsort(order)
    path = tmp_path / "average.obj"
    path.write_text(
        "".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in body.vertices[order])
        + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in inverse[body.faces])
    )
    bodies = [str(DEFAULT_REFMODELS / "small_slim.obj"), str(DEFAULT_REFMODELS / "tall_chubby.obj"), str(path)]
    out = tmp_path / "set"
    code, _, err = run(
        [
            "references",
            "build",
            "--base",
            str(REFERENCE_FOLDER / "base_mannequin.json"),
            "--targets",
            str(_targets_csv(tmp_path)),
            "--bodies",
            *bodies,
            "--up",
            "z",
            "-o",
            str(out),
        ],
        capsys,
    )
    assert_one_line_error(code, err, "average", "vertex order")
    assert not out.exists()
