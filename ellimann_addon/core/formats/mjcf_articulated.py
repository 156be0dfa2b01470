"""MJCF of a mannequin with joints: an articulated body that MuJoCo simulates.

One MuJoCo body per bone (SMPL's 24, named as ``core.mannequin.skeleton.JOINT_NAMES``), nested as the skeleton is, each
at its joint centre with world-aligned axes at rest; its pieces are its geoms: native ``ellipsoid`` geoms, and with
``cushions`` each cushion pair as a ``mesh`` geom (MuJoCo collides with a mesh's convex hull, which is the cushion), the
cushions that cross a joint split there into two halves, one per bone (``core.pose.posed_pieces``). The root (Pelvis)
has a free joint; every other joint is one hinge (knees, elbows, toes) or three hinges about its joint frame's x, y, z
(``skeleton.joint_frames``), applied in that order, so a pose's Euler angles in the joint frame (``pose.joint_angles``)
are exactly the hinges' values, with the anatomical ``range`` limits (``skeleton.limits``). Three hinges rather than a
ball: a ball joint's range is one cone angle, not the asymmetric ranges of a hip or a shoulder. Masses come from the
geoms' volumes at ``density`` (kg/m^3), scaled so that the pieces' overlaps count once (:func:`overlap_share`). The
mannequin's pieces collide with the floor and with anything added, not with each other (they overlap at rest). Poses
become keyframes (``<key name="t_pose" qpos=...>``; a motion gives one key per frame, ``walk 0``, ``walk 1``, ...); the
model itself is in the rest pose. With a skin (``--skin``) the file holds it bound to the 24 bodies, which move it as
``Skin.posed`` does (``core.formats.mjcf_skin``).
"""

import xml.etree.ElementTree as ET

import numpy as np

from ..constants import MJCF_CUSHION_LEVEL
from ..errors import ElliMannError
from ..files import atomic_write_text
from ..geometry.ellipsoid import volume as ellipsoid_volume
from ..geometry.mesh import volume as mesh_volume
from ..geometry.quaternion import rotation_to_quaternion
from ..mannequin.skeleton import CHILDREN, HINGES, JOINT_NAMES, ROOT, joint_frames, limits
from ..pose.kinematics import Pose, forward_kinematics, require_joints, rotation_angles
from ..pose.posed_pieces import PosingRig, union_volume
from .mjcf import CUSHION_RGBA, FRICTION, SIDE_RGBA, SOLREF, TIMESTEP, format_numbers, summary_comment
from .mjcf_skin import add_skin

BODY_DENSITY = 985.0  # kg/m^3, a human body's mean density
JOINT_DAMPING = 2.0  # N m s/rad: keeps a falling, limp body from flailing
JOINT_ARMATURE = 0.01  # kg m^2 of rotor inertia on each hinge (numerical stability of light distal bodies)
PIECE_CLASS = "ellimann"
MASS_SAMPLES = 100_000  # Monte Carlo samples of the union's volume (about 0.5% standard error)
EMPTY_BODY_MASS = 0.05  # kg
LIMIT_SOLREF = (0.002, 1.0)  # joint limits as stiff as contacts (MuJoCo clamps the time constant to 2 timesteps)


def hinge_axes(name):
    """Which joint-frame axes (0 x, 1 y, 2 z) a joint turns about in MJCF: x only for hinges, else all three."""
    return (0,) if name in HINGES else (0, 1, 2)


def articulated_mjcf(
    mannequin,
    poses=(),
    cushions=False,
    subdivisions=MJCF_CUSHION_LEVEL,
    floor=True,
    timestep=TIMESTEP,
    density=BODY_DENSITY,
    skin=None,
):
    """MJCF text of ``mannequin`` (with joints) as an articulated body, ``poses`` (core.pose.kinematics.Pose) as
    keyframes, ``skin`` (its ``core.skin.surface.Skin``) bound to the bodies."""
    mannequin.check()
    joints = require_joints(mannequin)
    if isinstance(density, bool) or not isinstance(density, (int, float)) or not 100.0 <= density <= 3000.0:
        raise ElliMannError(f"density: must be a number from 100 to 3000 kg/m^3, got {density!r}")
    rig = PosingRig(mannequin, cushions=cushions, subdivisions=subdivisions)
    frames, ranges = joint_frames(joints), limits(joints)
    share = overlap_share(rig)

    root = ET.Element("mujoco", model=mannequin.name or "ElliMann mannequin")
    root.append(
        ET.Comment(
            summary_comment(mannequin, mannequin.measure(), cushions, skin).replace(
                "Static: bodies have no joints.", "Articulated: SMPL's 24 bones, hinges with anatomical ranges."
            )
        )
    )
    ET.SubElement(root, "compiler", angle="radian", autolimits="true")
    ET.SubElement(root, "option", timestep=format_numbers([timestep]), integrator="implicitfast", cone="elliptic")
    default = ET.SubElement(root, "default")
    ET.SubElement(default, "geom", solref=format_numbers(SOLREF))
    pieces = ET.SubElement(default, "default", {"class": PIECE_CLASS})
    # contype 2, conaffinity 1: a piece meets the floor and objects (1, 1), never another piece.
    ET.SubElement(
        pieces,
        "geom",
        contype="2",
        conaffinity="1",
        condim="3",
        friction=format_numbers(FRICTION),
        group="1",
        density=format_numbers([density * share]),
    )
    ET.SubElement(
        pieces,
        "joint",
        type="hinge",
        damping=format_numbers([JOINT_DAMPING]),
        armature=format_numbers([JOINT_ARMATURE]),
        solreflimit=format_numbers(LIMIT_SOLREF),
    )

    asset = ET.SubElement(root, "asset")
    for side, rgba in SIDE_RGBA.items():
        ET.SubElement(asset, "material", name=f"ellimann_{side}", rgba=format_numbers(rgba, 4))
    ET.SubElement(asset, "material", name="ellimann_cushion", rgba=format_numbers(CUSHION_RGBA, 4))
    world = ET.SubElement(root, "worldbody")
    ET.SubElement(world, "light", name="sun", directional="true", pos="0 -2 4", dir="0 0.4 -1")
    if floor:
        ET.SubElement(
            asset,
            "texture",
            name="grid",
            type="2d",
            builtin="checker",
            width="256",
            height="256",
            rgb1=".85 .85 .85",
            rgb2=".7 .7 .7",
        )
        ET.SubElement(asset, "material", name="floor", texture="grid", texrepeat="8 8", reflectance="0")
        ET.SubElement(
            world,
            "geom",
            name="floor",
            type="plane",
            size="0 0 0.05",
            material="floor",
            friction=format_numbers(FRICTION),
        )

    topology = mannequin.topology
    quats = rotation_to_quaternion(mannequin.rotation)
    singles = topology.single_parts(cushions)
    bodies = {}

    def add_body(j, parent_element):
        parent = -1 if j == ROOT else int(np.flatnonzero([j in c for c in CHILDREN])[0])
        position = joints[j] - (joints[parent] if parent >= 0 else 0.0)
        body = ET.SubElement(parent_element, "body", name=JOINT_NAMES[j], pos=format_numbers(position))
        if j == ROOT:
            body.set("childclass", PIECE_CLASS)
            ET.SubElement(body, "freejoint", name=JOINT_NAMES[j])
        else:
            for k in hinge_axes(JOINT_NAMES[j]):
                ET.SubElement(
                    body,
                    "joint",
                    name=f"{JOINT_NAMES[j]}_{'xyz'[k]}",
                    axis=format_numbers(frames[j][:, k]),
                    range=format_numbers(ranges[j, k]),
                )
        if not any(rig.bones[i] == j for i in singles) and not any(mesh.bone == j for mesh in rig.meshes):
            # A bone without pieces (Spine3): a small point mass, as MuJoCo needs one on every moving body.
            ET.SubElement(
                body,
                "inertial",
                pos="0 0 0",
                mass=format_numbers([EMPTY_BODY_MASS]),
                diaginertia=format_numbers([EMPTY_BODY_MASS * 1e-4] * 3),
            )
        for i in singles:
            if rig.bones[i] == j:
                part = topology.parts[i]
                ET.SubElement(
                    body,
                    "geom",
                    name=part.name,
                    type="ellipsoid",
                    size=format_numbers(mannequin.semi_axes[i]),
                    pos=format_numbers(mannequin.center[i] - joints[j]),
                    quat=format_numbers(quats[i]),
                    material=f"ellimann_{part.side}",
                )
        for mesh in rig.meshes:
            if mesh.bone == j:
                ET.SubElement(
                    asset,
                    "mesh",
                    name=mesh.name,
                    vertex=format_numbers(mesh.vertices - joints[j], 8),
                    face=" ".join(map(str, mesh.faces.ravel())),
                )
                ET.SubElement(body, "geom", name=mesh.name, type="mesh", mesh=mesh.name, material="ellimann_cushion")
        bodies[j] = body
        for child in CHILDREN[j]:
            add_body(child, body)

    add_body(ROOT, world)
    if skin is not None:
        add_skin(root, skin, JOINT_NAMES, joints)
    if poses:
        keys = ET.SubElement(root, "keyframe")
        for pose, qpos in zip(poses, poses_qpos(poses, joints)):
            ET.SubElement(keys, "key", name=pose.name or "pose", qpos=format_numbers(qpos))
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def overlap_share(rig):
    """The union's volume over the sum of the pieces' volumes (< 1: pieces overlap), by Monte Carlo with a
    fixed seed: every geom's density is scaled by it, so the body's mass is the union's volume at the density."""
    body = rig.pose(Pose())
    single = body.mannequin.topology.single_parts(cushions=bool(rig.meshes))
    m = body.mannequin
    ellipsoids = (m.rotation[single], m.center[single], m.semi_axes[single])
    meshes = [(c.vertices, c.faces) for c in body.cushions]
    total = float(np.sum(ellipsoid_volume(m.semi_axes[single])) + sum(mesh_volume(v, f) for v, f in meshes))
    union, _ = union_volume(ellipsoids, meshes, samples=MASS_SAMPLES, seed=0)
    return union / total


def pose_qpos(pose, joints):
    """MuJoCo qpos of ``pose`` for :func:`articulated_mjcf`'s model: the root's position and quaternion, then
    each hinge's angle, in the order the bodies are nested (depth first, as MuJoCo numbers them)."""
    return poses_qpos([pose], joints)[0]


def poses_qpos(poses, joints):
    """(F, n): :func:`pose_qpos` of each of ``poses``, computed together (a clip's thousands of frames)."""
    rotations = np.stack([p.rotations for p in poses])
    world, _, posed = forward_kinematics(joints, rotations, np.stack([p.translation for p in poses]))
    angles = rotation_angles(rotations, joints)
    hinges = []

    def visit(j):
        if j != ROOT:
            hinges.extend((j, k) for k in hinge_axes(JOINT_NAMES[j]))
        for child in CHILDREN[j]:
            visit(child)

    visit(ROOT)
    joint, axis = np.array(hinges).T
    return np.concatenate([posed[:, ROOT], rotation_to_quaternion(world[:, ROOT]), angles[:, joint, axis]], axis=1)


def write_articulated_mjcf(mannequin, path, poses=(), cushions=False, skin=None):
    """Write :func:`articulated_mjcf` atomically."""
    atomic_write_text(path, articulated_mjcf(mannequin, poses, cushions, skin=skin))
    return path
