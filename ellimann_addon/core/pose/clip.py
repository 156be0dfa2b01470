"""A clip on a mannequin: its frames retargeted (``retarget``) and clamped into the joints' ranges, what the clamps
did per joint (how many frames, the worst angle, the range), and where the lowest foot is against the floor over
the clip, held on the floor on request (the root lifted or lowered by the foot's depth in each frame)."""

from dataclasses import dataclass

import numpy as np

from ..mannequin.skeleton import JOINT_NAMES, limits, part_bones
from .kinematics import Pose, clamp_rotations, forward_kinematics, require_joints
from .retarget import retarget

FLOOR_TOLERANCE = 0.001  # m: a foot this close to the floor is on it
SLIGHT_DEGREES = 0.1  # a joint axis clamped by less than this in every frame is named in one line, not summarised
FEET = ("L_Ankle", "R_Ankle", "L_Foot", "R_Foot")  # the bones whose pieces stand on the floor


@dataclass(frozen=True)
class ClampSummary:
    """One joint axis clamped over a clip: in how many of its frames, the worst angle (degrees, the one furthest
    beyond the range) and its frame (from 1), the range."""

    joint: str
    axis: str
    frames: int
    total: int
    worst: float
    frame: int
    low: float
    high: float

    @property
    def slight(self):
        """Whether it was beyond its range by less than SLIGHT_DEGREES in every frame (a hinge's rounding)."""
        return min(abs(self.worst - self.low), abs(self.worst - self.high)) < SLIGHT_DEGREES

    def __str__(self):
        return (
            f"{self.joint} about its {self.axis} axis in {self.frames} of {self.total} frames, worst "
            f"{self.worst:.1f} degrees (frame {self.frame}), range {self.low:.0f} to {self.high:.0f}"
        )


def clamp_summaries(angles, beyond, ranges):
    """The ClampSummary of each joint axis beyond its range in some frame: ``angles`` (F, 24, 3) radians, ``beyond``
    (F, 24, 3) bool, ``ranges`` (24, 3, 2) radians."""
    excess = np.maximum(ranges[..., 0] - angles, angles - ranges[..., 1])
    out = []
    for joint, axis in zip(*np.nonzero(beyond.any(axis=0))):
        frame = int(np.argmax(np.where(beyond[:, joint, axis], excess[:, joint, axis], -np.inf)))
        low, high = np.degrees(ranges[joint, axis])
        out.append(
            ClampSummary(
                JOINT_NAMES[joint],
                "xyz"[axis],
                int(beyond[:, joint, axis].sum()),
                len(angles),
                float(np.degrees(angles[frame, joint, axis])),
                frame + 1,
                float(low),
                float(high),
            )
        )
    return out


def lowest_foot(mannequin, joints, rotations, translations):
    """(F,): the z of the lowest point of the feet's pieces (ellipsoids: closed form) in each posed frame."""
    bones = part_bones(mannequin.topology)
    feet = np.nonzero(np.isin(bones, [JOINT_NAMES.index(n) for n in FEET]))[0]
    world, offset, _ = forward_kinematics(joints, rotations, translations)
    frame = world[:, bones[feet]] @ mannequin.rotation[feet]
    center = np.einsum("fnij,nj->fni", world[:, bones[feet]], mannequin.center[feet]) + offset[:, bones[feet]]
    reach = np.linalg.norm(frame[..., 2, :] * mannequin.semi_axes[feet], axis=-1)
    return (center[..., 2] - reach).min(axis=1)


@dataclass
class ClipOnMannequin:
    """A clip retargeted onto a mannequin: the poses (clamped, held on the floor if asked), the clamps per joint
    axis, the joints clamped in each frame ((F, 24) bool), the lowest foot's height over the floor in each frame
    before any hold (m), and whether it was held."""

    poses: list
    clamps: list
    clamped: np.ndarray
    lowest: np.ndarray
    held: bool

    def clamp_lines(self):
        """The clamps, a line per joint axis, those beyond by less than SLIGHT_DEGREES named together."""
        lines = [f"clamped to the limits: {clamp}" for clamp in self.clamps if not clamp.slight]
        slight = [f"{clamp.joint} {clamp.axis}" for clamp in self.clamps if clamp.slight]
        if slight:
            lines.append(f"clamped by less than {SLIGHT_DEGREES:g} degree: {', '.join(slight)}")
        return lines

    def floor_line(self, hint=""):
        """Where the lowest foot went over the clip; ``hint`` is added where it left the floor."""
        low, high = int(np.argmin(self.lowest)), int(np.argmax(self.lowest))
        below, above = -self.lowest[low], self.lowest[high]
        if self.held:
            moved = max(below, above, 0.0)
            return f"feet: held on the floor in every frame (the root moved by up to {100 * moved:.1f} cm)"
        if below <= FLOOR_TOLERANCE and above <= FLOOR_TOLERANCE:
            return "feet: the lowest foot stays on the floor (within 1 mm)"
        parts = []
        if below > FLOOR_TOLERANCE:
            parts.append(f"sinks up to {100 * below:.1f} cm below the floor (frame {low + 1})")
        if above > FLOOR_TOLERANCE:
            where = "it" if parts else "the floor"
            parts.append(f"floats up to {100 * above:.1f} cm above {where} (frame {high + 1})")
        return f"feet: over the clip the lowest foot {' and '.join(parts)}{hint}"


def clip_onto(mannequin, motion, match, keep_on_floor=False, name="clip"):
    """The ClipOnMannequin of ``motion`` (``retarget.SourceMotion``) on ``mannequin`` (with joints) as ``match``
    maps it: frames named '``name`` 1', '``name`` 2', ...; ElliMannError if the mannequin has no joints."""
    joints = require_joints(mannequin)
    identity = np.repeat(np.eye(3)[None, None], len(joints), axis=1)
    floor = float(lowest_foot(mannequin, joints, identity, np.zeros((1, 3)))[0])
    local, translations = retarget(motion, match, joints, floor)
    local, angles, beyond = clamp_rotations(local, joints)
    lowest = lowest_foot(mannequin, joints, local, translations) - floor
    if keep_on_floor:
        translations = translations.copy()
        translations[:, 2] -= lowest
    poses = [Pose(r, t, name=f"{name} {i}") for i, (r, t) in enumerate(zip(local, translations), start=1)]
    summaries = clamp_summaries(angles, beyond, limits(joints))
    return ClipOnMannequin(poses, summaries, beyond.any(axis=-1), lowest, keep_on_floor)
