"""glTF export keeps piece names and measurements in extras, exports only the mannequin, writes atomically."""

import os
import stat

import bpy
import numpy as np
import pytest

from ellimann_addon.blender.bridge import convert
from ellimann_addon.blender.services.files import export_gltf, write_mannequin
from ellimann_addon.core.errors import ElliMannError, MannequinError
from ellimann_addon.core.files import atomic_output
from ellimann_addon.core.formats.glb import EXTRAS_KEY, read_glb_json
from ellimann_addon.core.formats.table import write_file
from ellimann_addon.core.geometry.quaternion import quaternion_to_rotation
from ellimann_addon.core.measurements import MEASUREMENTS

# glTF is Y-up: Blender's exporter maps (x, y, z) -> (x, z, -y).
Z_UP_FROM_Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


@pytest.fixture
def mannequin(toy):
    toy.measurements = {"He": 161.0, "Sh": 48.0, "Br": 86.0, "Wa": 70.0, "Hi": 88.0}
    return toy


def test_pieces_keep_names_parts_and_frames(mannequin, tmp_path):
    collection = convert.mannequin_to_collection(mannequin)
    stranger = bpy.data.objects.new("not a part", None)
    bpy.context.scene.collection.objects.link(stranger)
    path = export_gltf(collection, tmp_path / "toy.glb")
    doc = read_glb_json(path)
    nodes = {n["name"]: n for n in doc["nodes"]}
    assert set(nodes) == set(mannequin.topology.names)  # only the mannequin's pieces
    assert len(doc["meshes"]) == 1  # one shared unit sphere: the node transform is the ellipsoid
    for i, part in enumerate(mannequin.topology):
        node = nodes[part.name]
        extras = node["extras"][EXTRAS_KEY]
        assert (extras["part"], extras["side"], extras["region"], extras["girth"], extras["partner"]) == (
            part.name,
            part.side,
            part.region,
            part.girth,
            part.partner,
        )
        assert extras["depends"] == [m for m in MEASUREMENTS if m in part.depends]
        assert np.allclose(extras["center_m"], mannequin.center[i], atol=1e-6)
        assert np.allclose(np.array(extras["axes"]).T, mannequin.rotation[i], atol=1e-6)
        assert np.allclose(extras["semi_axes_m"], mannequin.semi_axes[i], rtol=1e-6)
        # The node's own TRS, brought back to Z-up, is the same ellipsoid.
        x, y, z, w = node.get("rotation", (0.0, 0.0, 0.0, 1.0))  # glTF leaves out defaults
        scale = node.get("scale", (1.0, 1.0, 1.0))
        linear = Z_UP_FROM_Y_UP @ (quaternion_to_rotation([w, x, y, z]) * scale) @ Z_UP_FROM_Y_UP.T
        expected = mannequin.rotation[i] * mannequin.semi_axes[i]
        assert np.allclose(linear, expected, atol=1e-6)
        assert np.allclose(Z_UP_FROM_Y_UP @ node.get("translation", (0.0, 0.0, 0.0)), mannequin.center[i], atol=1e-6)


def test_measurements_travel_in_the_scene_extras(mannequin, tmp_path):
    collection = convert.mannequin_to_collection(mannequin)
    doc = read_glb_json(export_gltf(collection, tmp_path / "toy.glb"))
    scene = doc["scenes"][doc.get("scene", 0)]
    extras = scene["extras"][EXTRAS_KEY]
    assert extras["format"] == "ellimann.gltf-extras" and extras["version"] == 1
    assert extras["name"] == collection.name and extras["role"] == mannequin.role
    assert extras["target_cm"] == pytest.approx(mannequin.measurements)
    assert extras["measured_cm"] == pytest.approx(mannequin.measure(), rel=1e-5)


def test_export_leaves_no_trace_in_the_file(mannequin, tmp_path):
    collection = convert.mannequin_to_collection(mannequin)
    first = collection.objects[0]
    first["note"] = "the user's own value"
    keys = {o.name: set(o.keys()) for o in collection.objects} | {collection.name: set(collection.keys())}
    export_gltf(collection, tmp_path / "toy.glb")
    assert first["note"] == "the user's own value"
    assert {o.name: set(o.keys()) for o in collection.objects} | {collection.name: set(collection.keys())} == keys
    node = next(n for n in read_glb_json(tmp_path / "toy.glb")["nodes"] if n["name"] == first.name)
    assert node["extras"]["note"] == "the user's own value"  # the user's custom properties travel too
    assert [p.name for p in tmp_path.iterdir()] == ["toy.glb"]  # no temporary file left


def test_bad_input_writes_nothing(mannequin, tmp_path):
    collection = convert.mannequin_to_collection(mannequin)
    with pytest.raises(ElliMannError, match="glb"):
        export_gltf(collection, tmp_path / "toy.gltf")
    target = tmp_path / "toy.glb"
    target.write_bytes(b"previous")
    obj = next(o for o in collection.objects if o.ellimann.part_name == "3.a Pelvis")
    obj.scale.x = -obj.scale.x  # a left-handed frame is not an ellipsoid
    with pytest.raises(MannequinError, match="3.a Pelvis"):
        export_gltf(collection, target)
    assert target.read_bytes() == b"previous"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["toy.glb"]


@pytest.fixture
def umask():
    """A known umask (022: files 0644) for the test, the previous one restored afterwards."""
    previous = os.umask(0o022)
    yield 0o022
    os.umask(previous)


def test_every_format_gets_the_usual_permissions(mannequin, tmp_path, umask):
    paths = [tmp_path / f"toy.{ext}" for ext in ("glb", "blend", "obj", "json", "xml")]
    write_mannequin(mannequin, paths[:2])
    for path in paths[2:]:
        write_file(mannequin, path)
    modes = {p.suffix: stat.S_IMODE(p.stat().st_mode) for p in paths}
    assert modes == {p.suffix: 0o666 & ~umask for p in paths}  # mkstemp's 0600 would show here
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in paths)


def test_export_reads_parts_in_child_collections(mannequin, tmp_path):
    collection = convert.mannequin_to_collection(mannequin)
    bpy.context.view_layer.objects.active = collection.objects[0]
    bpy.ops.ellimann.build_cushions(subdivisions=1)
    doc = read_glb_json(export_gltf(collection, tmp_path / "toy.glb"))
    kinds = [n["extras"][EXTRAS_KEY]["kind"] for n in doc["nodes"]]
    assert kinds.count("CUSHION") == 3 and kinds.count("ELLIPSOID") == len(mannequin)


def test_a_failed_write_names_its_target_not_the_temporary_file(mannequin, tmp_path):
    """atomic_output raises OSErrors with filename = the path as given, whichever step failed."""
    blocked = tmp_path / "blocked.glb"
    (blocked / "inside").mkdir(parents=True)  # a folder in the way: the final rename fails
    paths = [str(tmp_path / "ok.blend"), str(blocked)]
    with pytest.raises(OSError) as raised:
        write_mannequin(mannequin, paths)
    assert raised.value.filename == str(blocked) and ".ellimann-" not in str(raised.value)
    for target, error in (
        (str(tmp_path / "a_file" / "m.blend"), "File exists"),  # a file where its folder should be
        (str(tmp_path / "empty.png"), "Blender wrote nothing"),
    ):
        (tmp_path / "a_file").touch()
        with pytest.raises(OSError, match=error) as raised, atomic_output(target):
            pass
        assert raised.value.filename == target
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file", "blocked.glb", "ok.blend"]


def test_write_mannequin_writes_blender_files_only(mannequin, tmp_path):
    for other in ("toy.json", "toy.obj"):
        with pytest.raises(ElliMannError, match=rf"'.*{other}' is not a .blend or .glb file \(the core writes"):
            write_mannequin(mannequin, [tmp_path / "toy.blend", tmp_path / other])
    assert list(tmp_path.iterdir()) == []
