"""The reference-set builder refuses what it cannot build from, in one line, before any fitting; and the
command line around it (``ellimann references``) writes nothing then."""

import dataclasses

import numpy as np
import pytest

from devkit.cli_runs import assert_one_line_error, run
from devkit.toy import make_toy_mannequin
from ellimann_addon.core.fitting.body_mesh import BodyMesh, connectivity_fingerprint, from_polygons, read_obj
from ellimann_addon.core.fitting.reference_build import ReferenceBuildError, central_body, validate_inputs
from ellimann_addon.core.geometry.mesh import from_scene_axes, icosphere
from ellimann_addon.core.mannequin.traces import FitSettings, PartTrace
from ellimann_addon.core.measurements import MEASUREMENTS

TARGETS = {"a": (150, 32, 86, 64, 84), "b": (170, 31, 85, 64, 85), "c": (160, 43, 117, 104, 117)}


def _sphere(name, scale=1.0):
    vertices, faces = icosphere(2)
    return from_polygons(name, vertices * scale, faces.tolist())


def _base(body):
    mannequin = make_toy_mannequin()
    traces = {
        part.name: PartTrace(
            "traced", len(body.vertices), body.edges_crc, np.arange(10 * i, 10 * i + 10), FitSettings()
        )
        for i, part in enumerate(mannequin.topology)
    }
    return mannequin.copy(role="base", name="Base", traces=traces)


@pytest.fixture
def inputs():
    bodies = [_sphere(name, 1.0 + 0.1 * i) for i, name in enumerate(TARGETS)]
    targets = {name: dict(zip(MEASUREMENTS, map(float, row))) for name, row in TARGETS.items()}
    return _base(bodies[0]), bodies, targets


def test_good_inputs_pass(inputs):
    assert validate_inputs(*inputs) == ("traced", len(inputs[1][0].vertices))


def _refused(base, bodies, targets, *words):
    with pytest.raises(ReferenceBuildError) as error:
        validate_inputs(base, bodies, targets)
    text = str(error.value)
    assert "\n" not in text
    for word in words:
        assert word in text, text


def test_fewer_than_three_bodies(inputs):
    base, bodies, targets = inputs
    _refused(base, bodies[:2], targets, "at least 3 bodies, got 2")


def test_another_vertex_count_names_both_counts(inputs):
    base, bodies, targets = inputs
    vertices, faces = icosphere(3)
    other = from_polygons("c", vertices, faces.tolist())
    _refused(base, bodies[:2] + [other], targets, "c:", f"{len(vertices)} vertices", f"with {len(bodies[0].vertices)}")


def test_a_shuffled_vertex_order_is_refused(inputs):
    base, bodies, targets = inputs
    order = np.random.default_rng(0).permutation(len(bodies[2].vertices))
    inverse = np.argsort(order)
    shuffled = from_polygons("c", bodies[2].vertices[order], inverse[bodies[2].faces].tolist())
    assert shuffled.edges_crc != bodies[2].edges_crc  # the same surface, other vertex numbers
    _refused(base, bodies[:2] + [shuffled], targets, "c:", "vertex order")


def test_a_body_that_is_not_closed(inputs):
    base, bodies, targets = inputs
    body = bodies[2]
    open_body = BodyMesh("c", body.vertices, body.faces[1:], body.edges_crc)
    _refused(base, bodies[:2] + [open_body], targets, "c:", "not closed")


def test_a_missing_target_row_and_two_bodies_with_the_same_targets(inputs):
    base, bodies, targets = inputs
    _refused(base, bodies, {k: v for k, v in targets.items() if k != "b"}, "no row for body 'b'")
    _refused(base, bodies, dict(targets, c=dict(targets["a"])), "'a' and 'c' have the same targets")
    _refused(base, bodies, dict(targets, c=dict(targets["c"], Wa=900.0)), "'c' Wa=900", "accepted range")


def test_a_base_without_recorded_selections_says_how_to_trace_again(inputs):
    base, bodies, targets = inputs
    _refused(base.copy(traces=None), bodies, targets, "no recorded selection", "Fit Ellipsoid")


def test_the_labelling_reference_is_the_body_nearest_the_targets_mean():
    from ellimann_addon.core.constants import REFERENCE_MEASUREMENTS

    assert central_body(list(REFERENCE_MEASUREMENTS), REFERENCE_MEASUREMENTS) == "average"


def test_the_fingerprint_ignores_face_order_and_start_not_vertex_numbers():
    assert connectivity_fingerprint([[0, 1, 2], [2, 1, 3]]) == connectivity_fingerprint([[1, 3, 2], [2, 0, 1]])
    assert connectivity_fingerprint([[0, 1, 2], [2, 1, 3]]) != connectivity_fingerprint([[0, 1, 3], [3, 1, 2]])


def test_an_obj_with_quads_reads_as_triangles_with_the_quads_fingerprint(tmp_path):
    path = tmp_path / "cube.obj"
    corners = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    quads = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    path.write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in corners)
        + "".join("f " + " ".join(f"{i}/1" for i in q) + "\n" for q in quads)
    )
    body = read_obj(path, up="z")
    assert body.name == "cube" and body.faces.shape == (12, 3)
    assert body.edges_crc == connectivity_fingerprint([[i - 1 for i in q] for q in quads])


# ------------------------------------------------------------------ the command line


def _files(inputs, tmp_path, targets_text=None):
    base, bodies, targets = inputs
    base.save(tmp_path / "base.json")
    paths = []
    for body in bodies:
        path = tmp_path / f"{body.name}.obj"
        path.write_text(
            "".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in body.vertices)
            + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in body.faces)
        )
        paths.append(str(path))
    csv = tmp_path / "targets.csv"
    csv.write_text(
        targets_text
        if targets_text is not None
        else "name,"
        + ",".join(MEASUREMENTS)
        + "\n"
        + "".join(f"{name}," + ",".join(f"{row[k]:g}" for k in MEASUREMENTS) + "\n" for name, row in targets.items())
    )
    return ["references", "build", "--base", str(tmp_path / "base.json"), "--targets", str(csv), "--bodies", *paths]


@pytest.mark.parametrize(
    "case, words",
    [
        ("two bodies", ["at least 3 bodies"]),
        ("missing row", ["no row for body 'c'"]),
        ("not a number", ["Hi='wide' is not a number"]),
        ("old base", ["no recorded selection"]),
        ("part added", ["has no recorded selection", "Fit Ellipsoid"]),
    ],
)
def test_the_command_refuses_in_one_line_and_writes_nothing(inputs, tmp_path, capsys, case, words):
    base, bodies, targets = inputs
    text = None
    if case == "missing row":
        text = "name,He,Sh,Br,Wa,Hi\na,150,32,86,64,84\nb,170,31,85,64,85\n"
    elif case == "not a number":
        text = "name,He,Sh,Br,Wa,Hi\na,150,32,86,64,84\nb,170,31,85,64,85\nc,160,43,117,104,wide\n"
    if case == "old base":
        base = base.copy(traces=None)
    elif case == "part added":  # a finer base: a part added to a traced one and never fitted
        base = base.copy(traces={name: trace for name, trace in list(base.traces.items())[1:]})
    args = _files((base, bodies, targets), tmp_path, text)
    if case == "two bodies":
        args = args[:-1]
    out = tmp_path / "set"
    code, _, err = run([*args, "-o", str(out)], capsys)
    assert_one_line_error(code, err, *words)
    assert not out.exists()


def test_check_reports_each_rm_of_the_shipped_set(capsys):
    code, out, err = run(["references", "check", "reference_blends"], capsys)
    assert code == 0, err
    assert "6 RMs" not in out and "5 RMs, manifest reference_set.json" in out
    assert (
        sum(
            line.startswith(("small_slim:", "tall_slim:", "small_chubby:", "tall_chubby:", "average:"))
            for line in out.splitlines()
        )
        == 5
    )


def test_check_flags_an_rm_off_its_targets(tmp_path, capsys):
    from devkit.synthetic import make_reference_mannequins
    from ellimann_addon.core.mannequin.clean import register_to_world
    from ellimann_addon.core.synthesis.manifest import Manifest, write_reference_set

    mannequins = [register_to_world(m) for m in make_reference_mannequins()[:3]]
    targets = {m.name: dict(m.measurements) for m in mannequins}
    targets[mannequins[0].name]["Hi"] *= 1.05
    write_reference_set(
        tmp_path, {m.name: m for m in mannequins}, dataclasses.replace(Manifest("x", list(targets)), targets_cm=targets)
    )
    code, _, err = run(["references", "check", str(tmp_path)], capsys)
    assert_one_line_error(code, err, mannequins[0].name, "Hi is off its target")


def test_voxel_iou_of_a_ball_in_a_ball_is_their_volume_ratio_and_of_a_ball_with_itself_one():
    from ellimann_addon.core.geometry.volume import BodyVolume, voxel_iou
    from ellimann_addon.core.mannequin.model import Mannequin
    from ellimann_addon.core.mannequin.topology import Part, Topology

    vertices, faces = icosphere(4)
    topology = Topology([Part("1.a Ball", "C", "body", True, ("He",))])

    def ball(radius, x=0.0):
        return Mannequin(topology, np.eye(3)[None], np.array([[x, 0.0, 0.0]]), np.full((1, 3), radius))

    grid = BodyVolume(0.1 * vertices, faces).grid(0.003, margin=0.02)
    assert voxel_iou(ball(0.1), grid=grid) == pytest.approx(1.0, abs=0.05)  # the mesh is a little inside
    assert voxel_iou(ball(0.05), grid=grid) == pytest.approx(0.125, abs=0.01)
    assert voxel_iou(ball(0.05, x=0.5), grid=grid) == 0.0
    assert voxel_iou(ball(0.05), 0.1 * vertices, faces) == pytest.approx(0.125, abs=0.02)  # from the mesh


# ------------------------------------------------------------------ axes: OBJ is Y up


def _y_up_copy(body, path):
    """``body`` written as Blender exports an OBJ (Y up, -Z forward)."""
    path.write_text(
        "".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in from_scene_axes(body.vertices))
        + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in body.faces)
    )
    return path


def test_a_body_exported_from_blender_reads_as_the_same_body_given_with_up_z(tmp_path):
    from tools.shipped.build_reference import DEFAULT_REFMODELS

    z_up = read_obj(DEFAULT_REFMODELS / "average.obj", up="z")
    y_up = read_obj(_y_up_copy(z_up, tmp_path / "average.obj"))
    assert np.array_equal(y_up.vertices, z_up.vertices) and np.array_equal(y_up.faces, z_up.faces)
    assert y_up.edges_crc == z_up.edges_crc
    in_cm = tmp_path / "cm.obj"
    in_cm.write_text(
        "".join(f"v {x * 100:.17g} {y * 100:.17g} {z * 100:.17g}\n" for x, y, z in z_up.vertices)
        + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in z_up.faces)
    )
    assert np.allclose(read_obj(in_cm, up="z", unit="cm").vertices, z_up.vertices, atol=1e-12)


@pytest.mark.parametrize(
    "change, words",
    [
        ("z up read as y", ["average.obj", "lies down", "pass --up z"]),
        ("millimetres", ["average.obj", "1590 m tall", "pass --unit mm"]),
        ("upside down", ["average.obj", "stands on its head"]),
    ],
)
def test_a_body_in_the_wrong_axes_or_unit_is_refused_in_one_line_before_fitting(tmp_path, capsys, change, words):
    from tools.shipped.build_reference import DEFAULT_REFMODELS

    body = read_obj(DEFAULT_REFMODELS / "average.obj", up="z")
    vertices = {
        "z up read as y": body.vertices,
        "millimetres": body.vertices,
        "upside down": body.vertices * [1, 1, -1],
    }
    scale = 1000.0 if change == "millimetres" else 1.0
    points = vertices[change] * scale if change == "z up read as y" else from_scene_axes(vertices[change] * scale)
    faces = body.faces[:, ::-1] if change == "upside down" else body.faces  # a mirror turns the winding
    (tmp_path / "average.obj").write_text(
        "".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in points)
        + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces)
    )
    others = [_y_up_copy(body, tmp_path / f"{name}.obj") for name in ("b", "c")]
    base = tmp_path / "base.json"
    _base(body).save(base)
    targets = tmp_path / "targets.csv"
    targets.write_text("name,He,Sh,Br,Wa,Hi\naverage,159,43,117,104,117\nb,150,32,86,64,84\nc,170,31,85,64,85\n")
    argv = ["references", "build", "--base", str(base), "--targets", str(targets), "-o", str(tmp_path / "set")]
    code, _, err = run([*argv, "--bodies", str(tmp_path / "average.obj"), *map(str, others)], capsys)
    assert_one_line_error(code, err, *words)
    assert "Warning" not in err and not (tmp_path / "set").exists()
