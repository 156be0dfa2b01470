"""The articulated MJCF: MuJoCo loads it, its keyframes put every geom where core posing puts the piece, its
hinges carry the limits, its mass is the union's volume at the body density, and a limp body falling under
gravity stays finite and within its joint limits."""

import numpy as np
import pytest

from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.formats.mjcf_articulated import BODY_DENSITY, articulated_mjcf, overlap_share, pose_qpos
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.skeleton import HINGES, JOINT_COUNT, JOINT_NAMES, PARENTS, limits
from ellimann_addon.core.pose import standard as poses
from ellimann_addon.core.pose.kinematics import pose_mannequin
from ellimann_addon.core.pose.posed_pieces import PosingRig, union_volume
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

mujoco = pytest.importorskip("mujoco")  # a dev dependency (requirements-dev.txt); CI always has it

LIMIT_SLACK = np.radians(2.0)  # MuJoCo's limits are soft constraints: a falling body presses into them a little


@pytest.fixture(scope="module")
def average():
    return Mannequin.load(REFERENCE_FOLDER / "average.json")


@pytest.fixture(scope="module")
def frames(average):
    return [poses.standard_pose(n, average.joints) for n in poses.STILL_POSES] + poses.walk(average.joints)[::8]


@pytest.fixture(scope="module")
def rig(average):
    return PosingRig(average, subdivisions=3)  # the MJCF's cushion level


@pytest.fixture(scope="module")
def model(average, frames):
    return mujoco.MjModel.from_xml_string(articulated_mjcf(average, frames, cushions=True))


def test_one_body_per_bone_hinges_with_their_ranges(average, model):
    assert sorted(model.body(b).name for b in range(1, model.nbody)) == sorted(JOINT_NAMES)  # and the world
    for b in range(2, model.nbody):  # nested as the skeleton is
        name = model.body(b).name
        parent = JOINT_NAMES[PARENTS[JOINT_NAMES.index(name)]]
        assert model.body(model.body_parentid[b]).name == parent, name
    hinges = 3 * (JOINT_COUNT - 1 - len(HINGES)) + len(HINGES)
    assert model.njnt == 1 + hinges and model.nq == 7 + hinges
    ranges = limits(average.joints)
    for j in range(1, model.njnt):
        joint = model.joint(j)
        name, axis = joint.name.rsplit("_", 1)
        assert np.allclose(model.jnt_range[j], ranges[JOINT_NAMES.index(name), "xyz".index(axis)], atol=1e-8)
        assert model.jnt_limited[j]


@pytest.mark.parametrize("index", range(6))
def test_keyframes_put_every_geom_where_posing_puts_its_piece(average, frames, model, rig, index):
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, index)
    mujoco.mj_kinematics(model, data)
    posed = pose_mannequin(average, frames[index])
    body = rig.pose(frames[index])
    for i, name in enumerate(average.topology.names):
        g = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
        if g >= 0:
            assert np.abs(data.geom_xpos[g] - posed.center[i]).max() < 1e-8, name
            assert np.abs(data.geom_xmat[g].reshape(3, 3) - posed.rotation[i]).max() < 1e-8, name
    for rest, mesh in zip(rig.meshes, body.cushions):  # a mesh's vertices ride on its geom's body
        b = model.geom_bodyid[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, mesh.name)]
        assert model.body(b).name == JOINT_NAMES[mesh.bone]
        moved = data.xpos[b] + (rest.vertices - average.joints[mesh.bone]) @ data.xmat[b].reshape(3, 3).T
        assert np.abs(moved - mesh.vertices).max() < 1e-8, mesh.name


def test_qpos_of_the_rest_pose_is_mujocos_rest(average, model):
    assert np.allclose(pose_qpos(poses.a_pose(average.joints), average.joints), model.qpos0, atol=1e-8)


def test_mass_is_the_union_volume_at_body_density(average, model, rig):
    body = rig.pose(poses.a_pose(average.joints))
    single = average.topology.single_parts(True)
    union, error = union_volume(
        (average.rotation[single], average.center[single], average.semi_axes[single]),
        [(c.vertices, c.faces) for c in body.cushions],
        100_000,
        seed=7,
    )
    mass = model.body_subtreemass[1]
    assert abs(mass - union * BODY_DENSITY) < 4.0 * error * BODY_DENSITY + 0.01 * mass
    assert 0.5 < overlap_share(rig) < 1.0  # the pieces overlap: their sum of volumes is more than the body


@pytest.mark.slow
def test_a_limp_body_falling_under_gravity_stays_finite_and_within_its_limits(model):
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 1)  # from the T-pose
    hinge = np.arange(1, model.njnt)
    address, low, high = model.jnt_qposadr[hinge], model.jnt_range[hinge, 0], model.jnt_range[hinge, 1]
    worst = 0.0
    for _ in range(1500):  # 1.5 s: falls, lands, settles
        mujoco.mj_step(model, data)
        q = data.qpos[address]
        worst = max(worst, float(np.max(np.maximum(low - q, q - high))))
    assert np.all(np.isfinite(data.qpos)) and np.all(np.isfinite(data.qvel))
    assert worst < LIMIT_SLACK
    assert data.qpos[2] < 0.5  # it fell


def test_a_mannequin_without_joints_or_a_bad_density_is_refused(average):
    with pytest.raises(ElliMannError, match="has no joints"):
        articulated_mjcf(average.copy(joints=None))
    with pytest.raises(ElliMannError, match="density"):
        articulated_mjcf(average, density=5.0)
