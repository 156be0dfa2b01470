"""A drape on a moving body: the colliders move as forward kinematics moves the pieces, the dress's pins ride on
the torso (the cloth follows the stride), the mannequin itself is left alone, refusals change nothing."""

import bpy
import numpy as np
import pytest

from devkit.blender_scene import state
from ellimann_addon.blender.services.drape import CLOTH_NAME, PIN_GROUP, DrapeSettings, drape, evaluated_vertices
from ellimann_addon.blender.services.drape_motion import PIECE_KEY, TORSO_JOINTS, body_motion
from ellimann_addon.blender.services.scene import add_mannequin
from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.skeleton import JOINT_INDEX, part_bones
from ellimann_addon.core.pose.kinematics import forward_kinematics
from ellimann_addon.core.pose.motion import clamped_motion
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

FRAMES = 9


@pytest.fixture(scope="module")
def average():
    return Mannequin.load(REFERENCE_FOLDER / "average.json")


@pytest.mark.slow
def test_the_dress_walks_with_the_body(average):
    collection = add_mannequin(average)
    before = {k: v for k, v in state()["objects"].items() if k in {o.name for o in collection.objects}}
    walk, _, loop = clamped_motion("walk", average.joints)
    result = drape(average, "tube_dress", DrapeSettings(frames=FRAMES, edge=0.05), motion=walk, loop=loop)
    assert {k: v for k, v in state()["objects"].items() if k in before} == before  # the mannequin is untouched
    motion = body_motion(walk, FRAMES, loop)
    world, offset, posed = forward_kinematics(average.joints, motion[-1].rotations, motion[-1].translation)
    bones = part_bones(average.topology)
    scene = bpy.context.scene
    assert scene.frame_current == FRAMES
    for obj in result.collection.children[0].objects:  # each collider where its piece went
        piece = obj[PIECE_KEY]
        if piece not in average.topology.index:
            continue
        bone = bones[average.topology.index[piece]]
        rest = (
            np.array([v.co[:] for v in obj.data.vertices]) @ np.array(obj.matrix_world)[:3, :3].T
            + np.array(obj.matrix_world)[:3, 3]
        )
        assert np.abs(evaluated_vertices(obj) - (rest @ world[bone].T + offset[bone])).max() < 1e-4
    garment = result.garment_object
    assert PIN_GROUP in garment.vertex_groups and garment.modifiers[1].name == CLOTH_NAME
    pins = result.garment.pins
    torso = posed[[JOINT_INDEX[name] for name in TORSO_JOINTS]]
    carried = result.vertices[pins]
    # The pins went with the torso: as far from its posed joints as they were from its rest joints.
    rest_torso = average.joints[[JOINT_INDEX[name] for name in TORSO_JOINTS]]
    rest_gap = np.linalg.norm(result.garment.vertices[pins][:, None] - rest_torso[None], axis=2).min(axis=1)
    posed_gap = np.linalg.norm(carried[:, None] - torso[None], axis=2).min(axis=1)
    assert np.abs(posed_gap - rest_gap).max() < 0.02
    assert carried[:, 1].mean() < result.garment.vertices[pins][:, 1].mean() - 0.05  # walked forward (-Y)


def test_a_motion_needs_joints_and_nothing_is_built_without(average):
    before = state()
    with pytest.raises(ElliMannError, match="has no joints"):
        drape(
            average.copy(joints=None),
            "tube_dress",
            DrapeSettings(frames=4, edge=0.05),
            motion=clamped_motion("sit", average.joints)[0],
        )
    assert state() == before


def test_the_command_line_refuses_a_motion_without_joints_in_one_line(tmp_path, capsys, toy):
    from devkit.cli_runs import assert_one_line_error, run

    toy.save(tmp_path / "toy.json")
    out = tmp_path / "x.blend"
    code, _, err = run(["drape", str(tmp_path / "toy.json"), "--pose", "walk", "-o", str(out)], capsys)
    assert_one_line_error(code, err, "joints", "has no joints")
    assert not out.exists()
    code, _, err = run(["drape", str(tmp_path / "toy.json"), "--pose", "dance", "-o", str(out)], capsys)
    assert code == 2 and "invalid choice: 'dance'" in err and not out.exists()  # argparse's usage error
