"""A drape on a moving body: the colliders of a drape (``services.drape``) bound to an armature of their own
that moves from the rest pose into a pose or a motion (``core.pose.motion.drape_motion``), and the garment's pins
carried by the torso, so the cloth follows a walking body.

The armature lives in the drape's collection (hidden), so the mannequin and its own armature are left as
they are; the colliders, which are the moving body, are shown (solid, in renders too). Each collider is
bound rigidly to its piece's bone (a cushion across a joint cut there into two halves, as ``services.rig``
does for the mannequin), by an Armature modifier before its Collision modifier, which therefore sees the
moving mesh; the skin collider (``core.drape.colliders.skin_collider``) is bound by the skin's own bone weights
(``Skin.bones``: linear-blend skinning, as ``Skin.posed`` computes it). The garment gets an Armature modifier
before its Cloth modifier:
Blender's cloth pulls pinned vertices to that deformed mesh, so the pins (a dress's straps) go where the
torso goes; the other vertices are the simulation's.
"""

import numpy as np

from ...core.drape.colliders import SKIN_COLLIDER
from ...core.geometry.cushion import cushion_name
from ...core.mannequin.skeleton import JOINT_INDEX, JOINT_NAMES, cross_joint_pairs
from ...core.pose.motion import arms_out, drape_motion, loop_drift
from .rig import bake_action, bare_armature, bind_across, bind_piece, bind_weights, check_rig
from .skin import skin_bone_weights

PIECE_KEY = "ellimann_piece"  # on a collider: the name of the piece it stands for (a part or a cushion)
SETTLE_FRAMES = 20  # frames from rest into the first pose (at most a third of the drape): slow enough for the cloth
# Arms hanging 5 degrees from vertical (attention, the walk) brush the dress's flanks, whose ease puts
# the cloth beyond the hips: held this much further out, they swing clear of it.
ARMS_OUT_DEGREES = 15.0
BODY_COLOR = (0.8, 0.78, 0.72, 1.0)
TORSO_JOINTS = ("Pelvis", "Spine1", "Spine2", "Spine3", "Neck", "L_Collar", "R_Collar")  # what carries the pins


def settle_frames(frames):
    return min(SETTLE_FRAMES, frames // 3)


def animate_drape(collection, colliders, garment_object, mannequin, poses, loop, frames, skin=None):
    """Bind a drape's colliders (``skin``: the core Skin of the skin collider, if it is one) and garment to a new
    hidden armature playing ``poses`` (from rest, see the module docstring) over frames 1..``frames``; returns the
    last frame's pose."""
    joints, bones = check_rig(mannequin)
    rig = bare_armature(f"{collection.name} Body", joints, collection)
    rig.hide_render = True
    topology = mannequin.topology
    names = topology.names
    crossing = {cushion_name(names[i], names[j]): (i, j, joint) for i, j, joint in cross_joint_pairs(topology)}
    pairs = {cushion_name(names[i], names[j]): i for i, j in topology.cushion_pairs}
    show_body(colliders)  # the moving body is what the drape shows: its colliders, solid
    for obj in colliders:
        piece = obj.get(PIECE_KEY, "")
        if piece == SKIN_COLLIDER and skin is not None:
            bind_weights(obj, rig, skin_bone_weights(skin))
        elif piece in crossing:
            i, j, joint = crossing[piece]
            bind_across(
                obj,
                rig,
                joints[joint],
                mannequin.center[j] - mannequin.center[i],
                JOINT_NAMES[bones[i]],
                JOINT_NAMES[bones[j]],
            )
        else:
            bind_piece(obj, rig, JOINT_NAMES[bones[topology.index[piece] if piece in topology.index else pairs[piece]]])
    bind_weights(garment_object, rig, nearest_joint_weights(garment_object, joints))
    motion = body_motion(poses, frames, loop)
    bake_action(
        rig,
        JOINT_NAMES,
        np.stack([p.rotations for p in motion]),
        np.stack([p.translation for p in motion]),
        f"{collection.name} motion",
    )
    return motion[-1]


def body_motion(poses, frames, loop):
    """The drape's body, frame by frame: ``poses`` with the arms ARMS_OUT_DEGREES further out, reached from
    rest over ``settle_frames(frames)`` frames, then held or looped (``core.pose.motion.drape_motion``)."""
    poses = arms_out(poses, ARMS_OUT_DEGREES)
    return drape_motion(poses, frames, settle_frames(frames), loop, loop_drift(poses) if loop else None)


def nearest_joint_weights(obj, joints):
    """{torso joint: (V,) 0/1}: each vertex of a mesh object fully on the torso joint nearest to it at rest."""
    matrix = np.array(obj.matrix_world)
    vertices = np.array([v.co[:] for v in obj.data.vertices]) @ matrix[:3, :3].T + matrix[:3, 3]
    torso = np.array([JOINT_INDEX[name] for name in TORSO_JOINTS])
    nearest = np.argmin(np.linalg.norm(vertices[:, None, :] - joints[torso][None], axis=2), axis=1)
    return {name: (nearest == k).astype(float) for k, name in enumerate(TORSO_JOINTS) if np.any(nearest == k)}


def show_body(colliders):
    """Show collider objects as the body (solid, in renders too): the skin the cloth lies on."""
    for obj in colliders:
        obj.display_type, obj.hide_render, obj.color = "SOLID", False, BODY_COLOR
        obj.hide_set(False)
