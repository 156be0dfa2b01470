"""The standard poses and the walk cycle, each a function of the mannequin's own rest joints.

``a_pose`` is the rest pose (the traced A-pose); ``t_pose``: upper arms and forearms horizontal in the coronal
plane, elbows straight, nothing else moves; ``attention``: arms hanging 5 degrees from vertical, clear of the
torso; ``sit``: hips and knees flexed 90 degrees (thighs horizontal, shins vertical), feet flat on the floor
(their rest orientation and height), the body lowered; ``walk``: a looping cycle, one stride (two steps) per
second at ``fps`` frames per second, arms swinging against the legs, the body carried forward. Every standard
pose is within the joint limits (tests check it on every Reference Mannequin).
"""

import numpy as np

from ..errors import ElliMannError
from ..mannequin.skeleton import JOINT_INDEX, joint_frames
from .kinematics import Pose, axis_angle, forward_kinematics, rotation_between

STILL_POSES = ("a_pose", "t_pose", "attention", "sit")
MOTIONS = ("walk",)
POSE_NAMES = STILL_POSES + MOTIONS
WALK_FPS = 24
ATTENTION_DEGREES = 5.0  # arms from vertical
_X, _Y, _Z = np.eye(3)


def _identity():
    return np.repeat(np.eye(3)[None], len(JOINT_INDEX), axis=0)


def _j(name):
    return JOINT_INDEX[name]


def _arm_pose(joints, direction_of_side):
    """Rotations that point each upper arm and forearm along ``direction_of_side(side)`` (elbows straight)."""
    rotations = _identity()
    for s in "LR":
        shoulder, elbow, wrist = (joints[_j(f"{s}_{n}")] for n in ("Shoulder", "Elbow", "Wrist"))
        target = direction_of_side(s)
        upper = rotation_between(elbow - shoulder, target)
        rotations[_j(f"{s}_Shoulder")] = upper
        # The forearm, in the upper arm's posed frame, must point where the upper arm pointed at rest.
        rotations[_j(f"{s}_Elbow")] = rotation_between(wrist - elbow, elbow - shoulder)
    return rotations


def t_pose(joints):
    """Upper arms and forearms horizontal, out to the sides (+X for the left), elbows straight."""
    return Pose(_arm_pose(joints, lambda s: _X if s == "L" else -_X), name="t_pose")


def attention(joints):
    """Arms straight, hanging ATTENTION_DEGREES from vertical in the coronal plane."""
    angle = np.radians(ATTENTION_DEGREES)

    def down(s):
        return np.array([np.sin(angle) * (1.0 if s == "L" else -1.0), 0.0, -np.cos(angle)])

    return Pose(_arm_pose(joints, down), name="attention")


def _bend_to_right_angle(thigh, shin):
    """Knee flexion (radians, about world X) that makes the shin perpendicular to the thigh."""
    # thigh . Rx(k) shin = A + B cos k + C sin k = 0, the root nearest a right angle.
    a = thigh[0] * shin[0]
    b = thigh[1] * shin[1] + thigh[2] * shin[2]
    c = thigh[2] * shin[1] - thigh[1] * shin[2]
    radius = np.hypot(b, c)
    if radius < abs(a):
        raise ElliMannError("sit: the legs of this mannequin cannot be bent to a right angle at the knee")
    phase = np.arctan2(c, b)
    roots = phase + np.array([1.0, -1.0]) * np.arccos(-a / radius)
    roots = np.mod(roots + np.pi, 2.0 * np.pi) - np.pi
    return float(roots[np.argmin(np.abs(roots - np.pi / 2))])


def sit(joints):
    """Thighs horizontal (forward, keeping their splay), shins vertical, feet as at rest, body lowered."""
    rotations = _identity()
    drop = []
    for s in "LR":
        hip, knee, ankle = (joints[_j(f"{s}_{n}")] for n in ("Hip", "Knee", "Ankle"))
        thigh, shin = knee - hip, ankle - knee
        flexion = _bend_to_right_angle(thigh, shin)
        bent = axis_angle(_X, flexion)
        shin_bent = bent @ shin
        forward = np.array([thigh[0], -np.hypot(thigh[1], thigh[2]), 0.0])
        forward /= np.linalg.norm(forward)
        down = -_Z
        # The hip's rotation maps the (thigh, bent shin) pair onto (forward, down): both pairs are orthonormal.
        rest = np.column_stack([thigh / np.linalg.norm(thigh), shin_bent / np.linalg.norm(shin_bent)])
        rest = np.column_stack([rest, np.cross(rest[:, 0], rest[:, 1])])
        posed = np.column_stack([forward, down, np.cross(forward, down)])
        hip_rotation = posed @ rest.T
        rotations[_j(f"{s}_Hip")] = hip_rotation
        rotations[_j(f"{s}_Knee")] = bent
        rotations[_j(f"{s}_Ankle")] = (hip_rotation @ bent).T  # the foot keeps its rest orientation
        ankle_posed = hip + hip_rotation @ (thigh + shin_bent)
        drop.append(ankle_posed[2] - ankle[2])
    return Pose(rotations, np.array([0.0, 0.0, -float(np.mean(drop))]), name="sit")


def a_pose(joints):
    return Pose(name="a_pose")


def walk(joints, fps=WALK_FPS, seconds=1.0):
    """The walk cycle: a list of ``round(fps * seconds)`` poses, one stride per second, looping (frame
    ``fps`` would be frame 0 again, one stride further forward). The root rises and falls with the legs; the
    body moves forward (-Y) by one stride per cycle (about 1.6 leg lengths), the feet sliding a little
    where a real stance foot would stay put (the joint angles are a smooth sinusoidal gait, not captured)."""
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not 24 <= fps <= 240:
        raise ElliMannError(f"fps: must be a number from 24 to 240 frames per second, got {fps!r}")
    count = int(round(fps * seconds))
    leg = float(
        np.linalg.norm(joints[_j("L_Hip")] - joints[_j("L_Knee")])
        + np.linalg.norm(joints[_j("L_Knee")] - joints[_j("L_Ankle")])
    )
    hip_swing, hip_bias = np.radians(20.0), np.radians(-5.0)  # a walking hip flexes more than it extends
    stride = 4.0 * leg * np.sin(hip_swing)  # two steps, each spanning both legs' swing
    rest = attention(joints).rotations
    hinge = joint_frames(joints)
    frames = []
    for i in range(count):
        phase = 2.0 * np.pi * i / (fps * 1.0)
        rotations = rest.copy()
        for s, shift in (("L", 0.0), ("R", np.pi)):
            p = phase + shift
            hip = hip_bias - hip_swing * np.sin(p)  # flexion (thigh forward) is negative about X
            # The knee bends most in mid-swing (the thigh moving forward), a little in stance.
            knee = np.radians(8.0) + np.radians(55.0) * max(0.0, np.cos(p)) ** 2
            ankle = np.radians(10.0) * np.sin(p) - 0.35 * knee * max(0.0, np.cos(p))
            arm = np.radians(18.0) * np.sin(p)  # the arm swings back (+) as this leg swings forward
            rotations[_j(f"{s}_Hip")] = axis_angle(_X, hip)
            rotations[_j(f"{s}_Knee")] = axis_angle(_X, knee)
            rotations[_j(f"{s}_Ankle")] = axis_angle(_X, ankle)
            rotations[_j(f"{s}_Shoulder")] = axis_angle(_X, arm) @ rest[_j(f"{s}_Shoulder")]
            rotations[_j(f"{s}_Elbow")] = (
                axis_angle(hinge[_j(f"{s}_Elbow")][:, 0], np.radians(12.0) + np.radians(10.0) * (1.0 - np.sin(p)))
                @ rest[_j(f"{s}_Elbow")]
            )
        rotations[_j("Spine1")] = axis_angle(_Z, np.radians(4.0) * np.sin(phase))  # the torso counter-rotates
        rotations[_j("Pelvis")] = axis_angle(_Z, -np.radians(4.0) * np.sin(phase))
        frames.append(Pose(rotations, np.array([0.0, -stride * i / count, 0.0]), name=f"walk {i}"))
    # The body rises and falls so that the lower ankle stays at its rest height (the stance foot on the floor).
    ankles = [_j("L_Ankle"), _j("R_Ankle")]
    posed = forward_kinematics(joints, np.stack([f.rotations for f in frames]))[2][:, ankles, 2]
    lift = joints[ankles, 2].min() - posed.min(axis=1)
    for frame, dz in zip(frames, lift):
        frame.translation[2] = dz
    return frames


_STILL = {"a_pose": a_pose, "t_pose": t_pose, "attention": attention, "sit": sit}


def check_pose_name(name):
    """ElliMannError naming the accepted poses unless ``name`` is one."""
    if name not in POSE_NAMES:
        raise ElliMannError(f"pose: unknown pose {name!r}; expected one of {', '.join(POSE_NAMES)}")
    return name


def standard_pose(name, joints):
    """A still standard pose (a_pose, t_pose, attention, sit) of a mannequin with rest ``joints``."""
    check_pose_name(name)
    if name in MOTIONS:
        raise ElliMannError(f"pose: {name!r} is a motion (a sequence of poses); use standard_motion")
    return _STILL[name](np.asarray(joints, dtype=float))


def standard_motion(name, joints, fps=WALK_FPS):
    """The frames of a standard pose: [the pose] for a still one, the cycle's poses for ``walk``."""
    check_pose_name(name)
    if name == "walk":
        return walk(np.asarray(joints, dtype=float), fps)
    return [standard_pose(name, joints)]
