"""The skin as the drape's collider (DrapeSettings.collider = "skin"): one shown mesh, the mannequin's skin at the
drape's skin level, that the dress lies on and the fit is measured against; on a moving body it follows its bones
by the skin's own weights exactly as Skin.posed computes it; the panel, the operator and the command line take the
setting; a mannequin whose pieces have no bones is refused in one line, nothing built."""

import bpy
import numpy as np
import pytest

from devkit.blender_scene import parts, select, state
from devkit.poses import make_apose_toy
from devkit.ui_recorder import draw_panel
from ellimann_addon import cli
from ellimann_addon.blender.bridge.convert import mannequin_to_collection
from ellimann_addon.blender.features.drape import panel as drape_panel
from ellimann_addon.blender.services.drape import DrapeSettings, drape, evaluated_vertices
from ellimann_addon.blender.services.drape_motion import PIECE_KEY, body_motion
from ellimann_addon.core.drape.colliders import SKIN_COLLIDER
from ellimann_addon.core.drape.fit_metrics import mesh_distance
from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.geometry.mesh import is_closed_manifold
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.pose.motion import clamped_motion
from ellimann_addon.core.settings import LEVELS
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

COARSE = {"edge": 0.05, "collider": "skin"}


@pytest.fixture(scope="module")
def average():
    return Mannequin.load(REFERENCE_FOLDER / "average.json")


def mesh_arrays(obj):
    vertices = np.array([v.co[:] for v in obj.data.vertices])
    faces = np.array([p.vertices[:] for p in obj.data.polygons])
    return vertices @ np.array(obj.matrix_world)[:3, :3].T + np.array(obj.matrix_world)[:3, 3], faces


@pytest.mark.slow
def test_the_dress_lies_on_the_skin_and_its_fit_is_measured_against_it(average):
    collection = mannequin_to_collection(average)
    before = {name: value for name, value in state()["objects"].items() if name in collection.all_objects}
    result = drape(average, "tube_dress", DrapeSettings(frames=8, **COARSE))
    assert result.skin is not None and result.skin.settings.voxel_mm == LEVELS["preview"]  # the drape's default
    (collider,) = result.collection.children[0].objects
    assert collider[PIECE_KEY] == SKIN_COLLIDER and collider.modifiers[0].type == "COLLISION"
    assert not collider.hide_get() and not collider.hide_render  # the body the dress lies on, shown
    vertices, faces = mesh_arrays(collider)
    assert np.allclose(vertices, result.skin.vertices, atol=1e-6) and np.array_equal(faces, result.skin.faces)
    assert is_closed_manifold(faces) and result.collider_triangles == len(faces)
    distance = mesh_distance(result.vertices, result.skin.vertices, result.skin.faces)[0]
    assert result.fit["count"] == len(distance) and result.fit["median"] == pytest.approx(np.median(distance))
    assert result.fit["penetrating_fraction"] <= 0.01 and result.fit["max_depth"] <= 0.005, result.fit
    assert "skin triangles" in result.summary()
    assert {name: value for name, value in state()["objects"].items() if name in before} == before


@pytest.mark.slow
def test_on_a_walking_body_the_skin_follows_its_bones_as_skin_posed_does(average):
    walk, _, loop = clamped_motion("walk", average.joints)
    frames = 9
    result = drape(average, "tube_dress", DrapeSettings(frames=frames, **COARSE), motion=walk, loop=loop)
    (collider,) = result.collection.children[0].objects
    assert bpy.context.scene.frame_current == frames
    posed = result.skin.posed(body_motion(walk, frames, loop)[-1])
    assert np.abs(evaluated_vertices(collider) - posed).max() < 1e-4  # Blender's armature, the core's weights
    assert np.abs(posed - result.skin.vertices).max() > 0.05  # and it did walk
    distance = mesh_distance(result.vertices, posed, result.skin.faces)[0]
    assert result.fit["median"] == pytest.approx(np.median(distance))  # measured on the skin as it ended


def test_pieces_whose_skin_falls_apart_cannot_be_a_skin_collider_and_nothing_is_built():
    toy = make_apose_toy()  # its head floats above its chest
    before = state()
    with pytest.raises(ElliMannError, match="skin: the body falls apart: 1.a Head touches no other piece"):
        drape(toy, "tube_dress", DrapeSettings(frames=4, **COARSE))
    assert state() == before
    for bad, field in (({"collider": "mesh"}, "collider"), ({"skin_level": "draft"}, "skin_level")):
        with pytest.raises(ElliMannError, match=f"^{field}: must be one of"):
            DrapeSettings(**bad).checked()


@pytest.mark.slow
def test_the_panel_and_the_operator_drape_on_the_skin(average):
    collection = mannequin_to_collection(average)
    select(parts(collection)["2.a Neck"])
    props = bpy.context.scene.ellimann_drape
    recorder = draw_panel(drape_panel.ELLIMANN_PT_drape)
    assert "collider" in recorder.props() and "cushions" in recorder.props() and "skin_level" not in recorder.props()
    props.frames, props.edge, props.collider = 4, 0.05, "skin"
    recorder = draw_panel(drape_panel.ELLIMANN_PT_drape)
    assert "skin_level" in recorder.props() and "cushions" not in recorder.props()
    assert props.settings().collider == "skin" and props.settings().skin_level == "preview"
    assert bpy.ops.ellimann.drape_garment() == {"FINISHED"}
    assert "skin triangles" in props.status


def run(args, capsys):
    code = cli.main(args)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.slow
def test_the_command_line_drapes_on_the_skin(average, tmp_path, capsys):
    source = tmp_path / "average.json"
    average.save(source)
    out = tmp_path / "dress.blend"
    args = ["drape", str(source), "--frames", "3", "--edge", "5", "--collider", "skin", "-o", str(out)]
    code, stdout, err = run([*args, "--skin-level", "preview"], capsys)
    assert code == 0, err
    assert "colliding with its skin (preview, 10 mm voxels)" in err and "skin triangles" in stdout and out.is_file()


def test_the_command_line_refuses_a_skin_level_without_the_skin_in_one_line(tmp_path, capsys):
    source = tmp_path / "toy.json"
    make_apose_toy().copy(name="toy").save(source)
    out = tmp_path / "x.blend"
    code, _, err = run(["drape", str(source), "--skin-level", "final", "-o", str(out)], capsys)
    assert code == 1 and len(err.strip().splitlines()) == 1 and "--skin-level" in err and "--collider skin" in err
    code, _, err = run(["drape", str(source), "--collider", "mesh", "-o", str(out)], capsys)
    assert code == 2 and "invalid choice" in err
    assert not out.exists()
