"""The correction's deformations: one smooth displacement field per measurement, each linear in its parameter,
so that a corrected body is ``rest + sum(theta_k * basis_k)``: arithmetic on the vertices, no remeshing.

Every field is a product of smooth functions (the body model's own bone weights, smoothstep profiles in height),
so no field has a kink at a section height or a seam between regions:

- He: a vertical scale about the floor.
- crotch_height: the legs stretched vertically and the trunk moved up by as much, He kept: a smoothstep ramp of
  the vertical scale across the crotch.
- Sh: the arms and collars moved sideways (each side by the parameter, metres).
- Br, Wa, Hi: horizontal scales of the trunk about its centre line, each by a profile in height that is 1 at its
  section and 0 at the next ones (a smooth partition of unity between Hi and Br, fading below Hi and above Br),
  the arms left out (their bone weights) and turned out about the shoulders by the angle that keeps them as far
  from the trunk as they were.
- neck: a horizontal scale about the neck's centre line, by the neck's bone weight.
- upper_arm, thigh, calf: scales across the limb's axis (shoulder-elbow, hip-knee, knee-ankle), by that
  bone's weight.
- arm_length: a stretch along the arm's axis from the shoulder joint, by the arm's weight.

The joints move with the surface around them (each the mean displacement of the vertices nearest to it).
"""

import numpy as np

from ..mannequin.skeleton import JOINT_COUNT, JOINT_INDEX

PARAMETERS = ("He", "Sh", "Br", "Wa", "Hi", "neck", "upper_arm", "thigh", "calf", "crotch_height", "arm_length")
TRUNK = ("Hi", "Wa", "Br")
FADE = 0.08  # He below Hi and above Br over which the trunk's profiles fade to 0
CROTCH_RAMP = 0.10  # He over which the legs' stretch turns into the trunk's lift
CENTRE_BIN = 0.01  # m: the trunk's centre line from horizontal slices this thick ...
CENTRE_SMOOTH = 5  # ... smoothed over this many slices
JOINT_RING = 1.3  # a joint moves as the vertices within this many times its depth (distance to the surface)
SIDES = ("L", "R")
ARM_FOLLOW = True
SIDE_SIGN = {"L": 1.0, "R": -1.0}


def smoothstep(t):
    t = np.clip(t, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def hat(z, low, mid, high):
    """A smooth hat: 0 below ``low`` and above ``high``, 1 at ``mid``, smoothstep between (C1 everywhere)."""
    rise = smoothstep((z - low) / (mid - low))
    fall = 1.0 - smoothstep((z - mid) / (high - mid))
    return np.where(z <= mid, rise, fall)


def _weight(weights, names):
    return weights[:, [JOINT_INDEX[n] for n in names]].sum(axis=1)


def _across(points, origin, axis):
    """The part of ``points - origin`` square to the unit ``axis``."""
    offset = points - origin
    return offset - np.outer(offset @ axis, axis)


def _unit(vector):
    return vector / np.linalg.norm(vector)


class Deformation:
    """The basis (K, V, 3) of a body's correction (PARAMETERS order) at ``vertices`` (V, 3, on z = 0) with
    ``joints`` (24, 3), ``weights`` (V, 24) its dense bone weights, ``fractions`` the section heights and
    ``crotch`` the crotch's height (m, for its ramp; default 0.46 He)."""

    def __init__(self, vertices, joints, weights, fractions, crotch=None):
        self.rest, self.joints = np.asarray(vertices, float), np.asarray(joints, float)
        self.height = float(np.ptp(self.rest[:, 2]))
        z, height = self.rest[:, 2] - self.rest[:, 2].min(), self.height
        self.arm = {s: _weight(weights, [f"{s}_{j}" for j in ("Shoulder", "Elbow", "Wrist", "Hand")]) for s in SIDES}
        basis = np.zeros((len(PARAMETERS), len(self.rest), 3))
        column = {key: i for i, key in enumerate(PARAMETERS)}
        basis[column["He"], :, 2] = z
        crotch = 0.46 * height if crotch is None else crotch
        basis[column["crotch_height"], :, 2] = self._leg_stretch(z, crotch)
        for side in SIDES:
            collar = weights[:, JOINT_INDEX[f"{side}_Collar"]]
            basis[column["Sh"], :, 0] += SIDE_SIGN[side] * (self.arm[side] + collar)
        self._trunk(basis, column, z, fractions)
        neck_weight = weights[:, JOINT_INDEX["Neck"]]
        neck, head = self.joints[JOINT_INDEX["Neck"]], self.joints[JOINT_INDEX["Head"]]
        basis[column["neck"]] = neck_weight[:, None] * _across(self.rest, neck, _unit(head - neck))
        for key, (start, end) in (
            ("upper_arm", ("Shoulder", "Elbow")),
            ("thigh", ("Hip", "Knee")),
            ("calf", ("Knee", "Ankle")),
        ):
            for side in SIDES:
                a, b = self.joints[JOINT_INDEX[f"{side}_{start}"]], self.joints[JOINT_INDEX[f"{side}_{end}"]]
                limb = weights[:, JOINT_INDEX[f"{side}_{start}"]]
                basis[column[key]] += limb[:, None] * _across(self.rest, a, _unit(b - a))
        for side in SIDES:
            shoulder = self.joints[JOINT_INDEX[f"{side}_Shoulder"]]
            arm = self.arm[side]
            tip = self.rest[np.argmax(np.where(arm > 0.5, np.linalg.norm(self.rest - shoulder, axis=1), -1.0))]
            axis = _unit(tip - shoulder)
            basis[column["arm_length"]] += arm[:, None] * np.outer((self.rest - shoulder) @ axis, axis)
        self.basis = basis
        self.flat = basis.reshape(len(PARAMETERS), -1)
        self.ring = self._joint_rings()

    @staticmethod
    def _leg_stretch(z, crotch):
        """z displacement of the legs' stretch: d/dz is 1 - ramp below the crotch's ramp and 0 above it, less the
        uniform scale that keeps the top where it was."""
        grid = np.linspace(0.0, z.max(), 2001)
        slope = 1.0 - smoothstep((grid - crotch) / (CROTCH_RAMP * z.max()) + 0.5)
        lift = np.concatenate([[0.0], np.cumsum(0.5 * (slope[1:] + slope[:-1]) * np.diff(grid))])
        return np.interp(z, grid, lift) - z * lift[-1] / z.max()

    def _trunk(self, basis, column, z, fractions):
        """The trunk's horizontal scales (Hi, Wa, Br) and the arms turned out with them."""
        height = self.height
        knots = [fractions["Hi"] - FADE, fractions["Hi"], fractions["Wa"], fractions["Br"], fractions["Br"] + FADE]
        knots = np.array(knots) * height
        arm_any = self.arm["L"] + self.arm["R"]
        trunk = np.clip(1.0 - arm_any, 0.0, 1.0)
        centre = self._centre_line(z, trunk)
        radial = self.rest[:, :2] - np.c_[np.zeros(len(z)), centre(z)]
        body = trunk > 0.5
        for i, key in enumerate(TRUNK):
            profile = hat(z, *knots[i : i + 3])
            basis[column[key], :, :2] = (trunk * profile)[:, None] * radial
            if not ARM_FOLLOW:
                continue
            for side in SIDES:
                arm = self.arm[side] > 0.5
                beside = body & (SIDE_SIGN[side] * self.rest[:, 0] > 0.0)
                beside &= (z >= z[arm].min()) & (z <= self.joints[JOINT_INDEX[f"{side}_Shoulder"], 2] - 0.1)
                if not beside.any():
                    continue
                # the trunk's side beside the arm, widened: the arm moves out by its mean widening (rigidly)
                slot = np.round(z[beside] / CENTRE_BIN).astype(int)
                edge = np.zeros(slot.max() + 1)
                np.maximum.at(edge, slot, SIDE_SIGN[side] * basis[column[key], beside, 0])
                shift = float(edge[np.unique(slot)].mean())
                basis[column[key], :, 0] += SIDE_SIGN[side] * self.arm[side] * shift

    def _centre_line(self, z, trunk):
        """The trunk's centre line y(z) (x = 0: the sagittal plane): the middle of the trunk's vertices' y
        extent in thin slices, smoothed."""
        kept = trunk > 0.5
        edges = np.arange(0.0, z.max() + CENTRE_BIN, CENTRE_BIN)
        slot = np.clip(np.digitize(z[kept], edges) - 1, 0, len(edges) - 2)
        y = self.rest[kept, 1]
        low = np.full(len(edges) - 1, np.inf)
        high = np.full(len(edges) - 1, -np.inf)
        np.minimum.at(low, slot, y)
        np.maximum.at(high, slot, y)
        filled = np.isfinite(low)
        middle = np.interp(np.arange(len(low)), np.nonzero(filled)[0], 0.5 * (low[filled] + high[filled]))
        kernel = np.ones(CENTRE_SMOOTH) / CENTRE_SMOOTH
        smooth = np.convolve(np.pad(middle, CENTRE_SMOOTH // 2, mode="edge"), kernel, mode="valid")
        heights = 0.5 * (edges[1:] + edges[:-1])
        return lambda at: np.interp(at, heights, smooth)

    def _joint_rings(self):
        """(24, V) each joint's share of each vertex's displacement: the vertices nearest to it."""
        ring = np.zeros((JOINT_COUNT, len(self.rest)))
        for j, joint in enumerate(self.joints):
            distance = np.linalg.norm(self.rest - joint, axis=1)
            near = distance <= JOINT_RING * distance.min() + 1e-3
            ring[j, near] = 1.0 / near.sum()
        return ring

    def displacement(self, theta):
        """(V, 3) displacement of the vertices for parameters ``theta`` (K,)."""
        return (np.asarray(theta, float) @ self.flat).reshape(-1, 3)

    def apply(self, theta):
        """(vertices (V, 3), joints (24, 3)) of the corrected body."""
        moved = self.displacement(theta)
        return self.rest + moved, self.joints + self.ring @ moved
