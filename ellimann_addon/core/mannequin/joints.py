"""A mannequin's joint centres: the JSON ``joints`` section, checks against the topology, joints taken from a
body's MakeHuman skeleton, interpolated by synthesis and moved with the pieces by a deformation.

Joints are a (24, 3) array in SMPL order (``core.mannequin.skeleton.JOINT_NAMES``), metres, rest pose. A joint follows
its anchor part (``core.mannequin.skeleton.JOINT_ANCHORS``): synthesis gives it that part's IDW weights and proportional
scales (as the part's centre), and a deformation that changes pieces (exact mode, the reference build's last
adjustment) moves it as a point fixed in the anchor's normalised frame: p' = c' + R' D' D^-1 R^T (p - c).
"""

import numpy as np

from ..constants import CENTER_LIMIT
from ..errors import MannequinError, Problem
from .skeleton import (
    CHILDREN,
    JOINT_ANCHORS,
    JOINT_COUNT,
    JOINT_NAMES,
    JOINT_TWINS,
    MAKEHUMAN_JOINTS,
    PARENTS,
    bone_problems,
    joint_side,
    part_bones,
)

SECTION_VERSION = 1
SKELETON = "smpl24"
# A joint lies at most this far (m) outside the box of the pieces on its bone, its parent's and its children's.
JOINT_REACH = 0.05
JOINT_SIDES = tuple(joint_side(name) for name in JOINT_NAMES)  # 'L', 'R' or 'C' of each joint


def joints_to_dict(joints):
    """The JSON ``joints`` section of (24, 3) joints."""
    return {
        "version": SECTION_VERSION,
        "skeleton": SKELETON,
        "names": list(JOINT_NAMES),
        "positions": np.asarray(joints, dtype=float).tolist(),
    }


def joints_from_dict(data):
    """(24, 3) joints from a ``joints`` section (None if absent); MannequinError naming the field otherwise."""
    if data is None:
        return None

    def bad(field, message):
        return MannequinError([Problem("", f"joints.{field}" if field else "joints", message)])

    if not isinstance(data, dict):
        raise bad("", "must be an object with version, skeleton, names and positions (or absent)")
    version = data.get("version")
    if isinstance(version, bool) or version != SECTION_VERSION:
        raise bad("version", f"is {version!r}; this ElliMann reads joints version {SECTION_VERSION}")
    if data.get("skeleton") != SKELETON:
        raise bad("skeleton", f"is {data.get('skeleton')!r}; expected '{SKELETON}' (SMPL's 24 joints)")
    if data.get("names") != list(JOINT_NAMES):
        raise bad("names", f"must be SMPL's {JOINT_COUNT} joints in order ({', '.join(JOINT_NAMES[:3])}, ...)")
    try:
        positions = np.array(data.get("positions"), dtype=float)
    except (TypeError, ValueError, OverflowError, RecursionError):
        positions = None
    if positions is None or positions.shape != (JOINT_COUNT, 3):
        raise bad("positions", f"must be a {JOINT_COUNT}x3 array of joint centres in metres")
    return positions


def joint_problems(mannequin):
    """Problems of a mannequin's joints (none if it has none): shape, finite, plausible, a bone for every part,
    and every joint near the pieces of its own, its parent's and its children's bones (joints of another
    mannequin or topology are refused)."""
    joints = mannequin.joints
    if joints is None:
        return []
    joints = np.asarray(joints)
    if joints.shape != (JOINT_COUNT, 3):
        return [Problem("", "joints", f"has shape {joints.shape}; expected ({JOINT_COUNT}, 3)")]
    if not np.all(np.isfinite(joints)):
        name = JOINT_NAMES[int(np.argwhere(~np.isfinite(joints))[0][0])]
        return [Problem("", "joints", f"{name} contains NaN or infinity")]
    if np.any(np.abs(joints) > CENTER_LIMIT):
        name = JOINT_NAMES[int(np.argwhere(np.abs(joints) > CENTER_LIMIT)[0][0])]
        return [
            Problem(
                "",
                "joints",
                f"{name} is too far from the origin (accepted range {-CENTER_LIMIT:g} to {CENTER_LIMIT:g} m)",
            )
        ]
    problems = bone_problems(mannequin.topology)
    if problems:
        return problems
    if mannequin.semi_axes.shape != (len(mannequin.topology), 3) or not np.all(np.isfinite(mannequin.semi_axes)):
        return []  # the geometry's own problems are reported
    from ..geometry.ellipsoid import bounds

    low, high = bounds(mannequin.rotation, mannequin.center, mannequin.semi_axes)
    bones = part_bones(mannequin.topology)
    out = []
    for j, name in enumerate(JOINT_NAMES):
        near = {j, *CHILDREN[j]} | ({PARENTS[j]} if PARENTS[j] >= 0 else set())
        pieces = np.isin(bones, list(near))
        if not pieces.any():
            continue
        lo, hi = low[pieces].min(axis=0) - JOINT_REACH, high[pieces].max(axis=0) + JOINT_REACH
        if np.any(joints[j] < lo) or np.any(joints[j] > hi):
            out.append(
                Problem(
                    "",
                    "joints",
                    f"{name} at {np.round(joints[j], 3).tolist()} m is not where the "
                    f"pieces of its bones are (the joints belong to another mannequin or "
                    f"topology)",
                )
            )
    return out


def joints_from_makehuman(bone_heads):
    """(24, 3) SMPL joints from a MakeHuman skeleton's bone heads ({bone: xyz}, e.g. one body of
    ``refmodels/skeleton.json``), each the mean of ``skeleton.MAKEHUMAN_JOINTS``' bones."""
    return np.array([np.mean([bone_heads[b] for b in MAKEHUMAN_JOINTS[name]], axis=0) for name in JOINT_NAMES])


def mirror_joints(joints, source="L"):
    """Joints with the other side replaced by the mirror image (across x = 0) of ``source``'s, and the central
    joints on x = 0: as ``core.mannequin.clean.symmetrize`` makes the pieces."""
    joints = np.array(joints, dtype=float)
    mirrored = joints[..., JOINT_TWINS, :] * np.array([-1.0, 1.0, 1.0])
    other = [i for i, side in enumerate(JOINT_SIDES) if side not in ("C", source)]
    joints[..., other, :] = mirrored[..., other, :]
    joints[..., [i for i, side in enumerate(JOINT_SIDES) if side == "C"], 0] = 0.0
    return joints


def anchor_indices(topology):
    """(24,) index of each joint's anchor part in ``topology``; MannequinError if one is missing."""
    missing = [
        Problem(JOINT_ANCHORS[n], "joints", f"is the anchor of joint {n} and is not in the topology")
        for n in JOINT_NAMES
        if JOINT_ANCHORS[n] not in topology.index
    ]
    if missing:
        raise MannequinError(missing)
    return np.array([topology.index[JOINT_ANCHORS[n]] for n in JOINT_NAMES])


def follow_pieces(joints, anchors, before, after):
    """Joints (..., 24, 3) moved by a deformation of the pieces: each fixed in its anchor's normalised frame.

    ``before`` and ``after`` are (rotation (..., n, 3, 3), center (..., n, 3), semi_axes (..., n, 3)) of the
    pieces; ``anchors`` (24,) part indices (:func:`anchor_indices`).
    """

    def take(rotation, center, semi_axes):
        return (
            np.take(np.asarray(rotation, dtype=float), anchors, axis=-3),
            np.take(np.asarray(center, dtype=float), anchors, axis=-2),
            np.take(np.asarray(semi_axes, dtype=float), anchors, axis=-2),
        )

    (r0, c0, d0), (r1, c1, d1) = take(*before), take(*after)
    # Sums over three terms written out, in a fixed order: a row gets the same bits in any batch.
    offset = np.asarray(joints, dtype=float) - c0
    local = (
        r0[..., 0, :] * offset[..., 0, None]
        + r0[..., 1, :] * offset[..., 1, None]
        + r0[..., 2, :] * offset[..., 2, None]
    ) / d0
    scaled = local * d1
    return (
        c1 + r1[..., 0] * scaled[..., 0, None] + r1[..., 1] * scaled[..., 1, None] + r1[..., 2] * scaled[..., 2, None]
    )
