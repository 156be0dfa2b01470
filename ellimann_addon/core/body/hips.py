"""The body skin's bone weights where the hips bend: plain linear-blend skinning (what glTF and FBX take) that keeps
the volume when sitting.

The body model's own weights (core.synthesis.bodies: MakeHuman's 104 bones summed on the 24 joints) bend a thigh
at the hip joint's level; sitting (hips and knees at 90 degrees) then folds the thigh's front into the belly and
loses 5-6.5 % of the volume. Here the share between the pelvis and each thigh (the vertices' Pelvis + L_Hip +
R_Hip weight, every other joint's weight kept) is re-drawn across a blend plane of each hip, as today's smooth skin
bends (core.skin.skinning): the plane through the point HIP_DROP of the thigh's length down the thigh from the hip
joint, square to the thigh turned about world X by a tilt, its ramp a smoothstep HIP_HALF of the thigh's length
either side; a thigh's share faded in across the sagittal plane over SIDE_WIDTH. The tilt (front higher, back
lower, as the groin and gluteal folds run) is the one at which the skin keeps its volume in ``sit``: found per skin
by the secant method within MAX_TILT, the best tried kept (the change of volume is, to first order in the bend, the
flux of the bend's motion through where the blend runs round the limb: tilting the plane moves it).
"""

import numpy as np

from ..geometry.mesh import volume
from ..mannequin.skeleton import JOINT_INDEX
from ..pose.kinematics import bone_matrices
from ..pose.motion import clamped_motion

# (drop, half-width) of the hips' planes, each a share of the thigh's length (hip to knee joint): the plane's point
# that far down the thigh from the hip joint, its ramp that wide either side; tried in turn until the volume is
# kept (a heavy belly over the thighs needs the lower, narrower bend)
PLANES = ((0.37, 0.22), (0.5, 0.15))
SIDE_WIDTH = 0.02  # m across the sagittal plane over which a thigh's share fades in
MAX_TILT = np.radians(60.0)
FIRST_TILT = np.radians(-30.0)  # the search's first two tilts: none and this one
SECANT_STEPS = 8
SCAN = tuple(np.radians([-45.0, -22.5, -15.0, -7.5, 15.0]))  # tilts tried when no secant search keeps the volume
TOLERANCE = 0.005  # of the volume: a tilt that keeps it this well is found (the gentler plane first)
INFLUENCES = 4
HIPS = (("L", 1.0), ("R", -1.0))


def _smoothstep(t):
    t = np.clip(t, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def hip_weights(vertices, joints, dense, tilt, plane=PLANES[0]):
    """(V, 24) ``dense`` weights with the pelvis's and the thighs' shares re-drawn across the hips' planes
    (``plane``: (drop, half-width), shares of the thigh's length) tilted by ``tilt`` (radians about world X;
    negative: the front higher)."""
    drop, half = plane
    pelvis = JOINT_INDEX["Pelvis"]
    hips = [JOINT_INDEX[f"{side}_Hip"] for side, _ in HIPS]
    total = dense[:, [pelvis, *hips]].sum(axis=1)
    c, s = np.cos(tilt), np.sin(tilt)
    turn = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    out = np.array(dense, float)
    for (side, sign), hip in zip(HIPS, hips):
        thigh = joints[JOINT_INDEX[f"{side}_Knee"]] - joints[hip]
        length = float(np.linalg.norm(thigh))
        normal = turn @ (thigh / length)
        origin = joints[hip] + drop * thigh
        rho = _smoothstep((vertices - origin) @ normal / (2.0 * half * length) + 0.5)
        out[:, hip] = total * rho * _smoothstep(sign * vertices[:, 0] / SIDE_WIDTH + 0.5)
    out[:, pelvis] = total - out[:, hips].sum(axis=1)
    return out


def largest(dense, count=INFLUENCES):
    """(joint index (V, count), weight (V, count)): the ``count`` largest weights of each vertex, renormalized."""
    order = np.argsort(-dense, axis=1, kind="stable")[:, :count]
    kept = np.take_along_axis(dense, order, axis=1)
    return order, kept / kept.sum(axis=1, keepdims=True)


def skinned(vertices, joints, index, weight, pose):
    """The vertices in ``pose`` by linear-blend skinning on (``index``, ``weight``) about ``joints``."""
    matrices = bone_matrices(joints, pose)[:, :3, :]
    homogeneous = np.c_[vertices, np.ones(len(vertices))]
    moved = np.einsum("vkij,vj->vki", matrices[index], homogeneous)
    return np.einsum("vk,vki->vi", weight, moved)


def balanced_bones(vertices, faces, joints, dense):
    """((joint index, weight) (V, 4) each, (drop, half-width, tilt), sit's volume change): the hips' planes
    (PLANES in turn) tilted so that the skin keeps its volume in ``sit``, the best tried when none does."""
    sit = clamped_motion("sit", joints)[0][0]
    rest = volume(vertices, faces)
    tried = {}

    def change(plane, tilt):
        if (plane, tilt) not in tried:
            bones = largest(hip_weights(vertices, joints, dense, tilt, plane))
            tried[plane, tilt] = (volume(skinned(vertices, joints, *bones, sit), faces) / rest - 1.0, bones)
        return tried[plane, tilt][0]

    for plane in PLANES:
        a, fa = 0.0, change(plane, 0.0)
        b, fb = FIRST_TILT, change(plane, FIRST_TILT)
        for _ in range(SECANT_STEPS):
            if abs(fb) <= TOLERANCE or fb == fa:
                break
            a, fa, b = b, fb, float(np.clip(b - fb * (b - a) / (fb - fa), -MAX_TILT, MAX_TILT))
            fb = change(plane, b)
        if min(abs(found) for found, _ in tried.values()) <= TOLERANCE:
            break
    else:  # no tilt keeps it: where the change is least (a heavy belly over the thighs: a greatest loss)
        for tilt in SCAN:
            change(PLANES[-1], tilt)
    best = min(tried, key=lambda key: abs(tried[key][0]))
    return tried[best][1], (*best[0], best[1]), tried[best][0]
