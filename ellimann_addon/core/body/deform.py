"""The correction's deformations: one smooth displacement field per measurement, each linear in its parameter,
so that a corrected body is ``rest + sum(theta_k * basis_k)``: arithmetic on the vertices, no remeshing.

Every field is a product of smooth functions (bone weights smoothed over the mesh, smooth profiles in height), so
no field has a kink at a section height or a seam between regions:

- He: a vertical scale about the floor.
- crotch_height: the legs stretched vertically and the trunk moved up by as much, He kept: a smoothstep ramp of
  the vertical scale across the crotch.
- Sh: the arms moved sideways (each side by the parameter, metres) and the shoulder girdle widened under them,
  its side at the shoulders by GIRDLE of that (an x-scale of the trunk by a profile 0 at the waist, 1 from the
  shoulder joints to the neck joint), the neck and head left out.
- Br, Wa, Hi: horizontal scales of the trunk split between width and depth (SPLIT; the depth about a pivot that
  gives the front FRONT_SHARE of it), each by a clamped cubic spline in height (:func:`cardinal`: 1 at its
  section, 0 at the others', at HIP_FADE below the hips and at the neck joint), the arms left out (their bone
  weights) and moved out rigidly by the trunk's mean widening beside them.
- neck: a horizontal scale about the neck's centre line, by the neck's bone weight.
- upper_arm, thigh, calf: scales across the limb's axis (shoulder-elbow, hip-knee, knee-ankle), by that
  bone's weight.
- arm_length: a stretch along the arm's axis from the shoulder joint, by the arm's weight.

The joints move with the surface around them (each the mean displacement of the vertices nearest to it).
:func:`smoothed` spreads the bone weights the fields use over the mesh (once per set); :func:`abducted` raises
the arms about the shoulders (a pose: core.body.plausible raises them to clear a wide trunk).
"""

import numpy as np

from ..mannequin.skeleton import JOINT_INDEX

PARAMETERS = ("He", "Sh", "Br", "Wa", "Hi", "neck", "upper_arm", "thigh", "calf", "crotch_height", "arm_length")
TRUNK = ("Hi", "Wa", "Br")
HIP_FADE = 0.12  # He below Hi over which the hips' profile fades to 0 (the upper thighs widen with the hips)
# how a girth's change splits between the section's width (x) and depth (y), as relative scales per unit: the 80
# bank bodies of each sex (../shared/bodies) widen as girth^0.8-1.0 and deepen as girth^1.0-1.4
SPLIT = {"Br": (0.9, 1.1), "Wa": (0.85, 1.25), "Hi": (0.9, 1.3)}
# the share of a girth's change in depth that moves the front (the rest moves the back): the bank's bodies'
# bellies grow forward (0.6-0.65 of the waist's depth change at the front), their buttocks backward (0.4)
FRONT_SHARE = {"Br": 0.55, "Wa": 0.6, "Hi": 0.4}
GIRDLE = 0.75  # the trunk's side at the shoulders moves out by this much of the arms' move (the bank: 0.69-0.76)
CROTCH_RAMP = 0.10  # He over which the legs' stretch turns into the trunk's lift
CENTRE_BIN = 0.01  # m: the trunk's front and back from horizontal slices this thick ...
CENTRE_SMOOTH = 5  # ... smoothed over this many slices
JOINT_RING = 1.3  # a joint moves as the vertices within this many times its depth (distance to the surface)
SIDES = ("L", "R")
SIDE_SIGN = {"L": 1.0, "R": -1.0}
SMOOTH_ROUNDS = 60  # neighbour averagings of the bone weights the deformations use (not the skinning's)


def smoothstep(t):
    t = np.clip(t, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def hat(z, low, mid, high):
    """A smooth hat: 0 below ``low`` and above ``high``, 1 at ``mid``, smoothstep between (C1 everywhere)."""
    rise = smoothstep((z - low) / (mid - low))
    fall = 1.0 - smoothstep((z - mid) / (high - mid))
    return np.where(z <= mid, rise, fall)


def cardinal(z, knots, k):
    """The clamped cubic spline through 1 at ``knots[k]`` and 0 at the other knots, its slope 0 at the first and
    last knot and 0 outside them: C2 between the ends, C1 at them. A girth's profile: its scale passes through
    each section with the slope the neighbours give, so a section is no ridge (a hat's flat top between steep
    flanks drew a belt at each section)."""
    knots = np.asarray(knots, float)
    n = len(knots)
    h = np.diff(knots)
    values = np.zeros(n)
    values[k] = 1.0
    # the slopes m_i of a C2 cubic Hermite interpolant, m_0 = m_{n-1} = 0: h_i m_{i-1} + 2 (h_{i-1} + h_i) m_i
    # + h_{i-1} m_{i+1} = 3 (h_i d_{i-1} + h_{i-1} d_i) at the interior knots, d_i the chords' slopes
    chord = np.diff(values) / h
    system = np.zeros((n, n))
    rhs = np.zeros(n)
    system[0, 0] = system[-1, -1] = 1.0
    for i in range(1, n - 1):
        system[i, i - 1], system[i, i], system[i, i + 1] = h[i], 2.0 * (h[i - 1] + h[i]), h[i - 1]
        rhs[i] = 3.0 * (h[i] * chord[i - 1] + h[i - 1] * chord[i])
    slopes = np.linalg.solve(system, rhs)
    z = np.asarray(z, float)
    piece = np.clip(np.searchsorted(knots, z) - 1, 0, n - 2)
    t = (z - knots[piece]) / h[piece]
    h00, h10, h01, h11 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t, -2 * t**3 + 3 * t**2, t**3 - t**2
    curve = h00 * values[piece] + h10 * h[piece] * slopes[piece] + h01 * values[piece + 1]
    curve += h11 * h[piece] * slopes[piece + 1]
    return np.where((z <= knots[0]) | (z >= knots[-1]), 0.0, curve)


def plateau(z, low, start, end, high):
    """0 below ``low`` and above ``high``, 1 from ``start`` to ``end``, smoothstep between (C1 everywhere)."""
    rise = smoothstep((z - low) / (start - low))
    fall = 1.0 - smoothstep((z - end) / (high - end))
    return np.where(z <= end, rise, fall)


def smoothed(field, faces, rounds=SMOOTH_ROUNDS):
    """``field`` (V, ...) averaged ``rounds`` times with its mesh neighbours (each round: half its own value, half
    its neighbours' mean over the edges of ``faces``): a bone weight's seam spread over more rings of triangles
    where the mesh is fine (the armpits' crease). Sums in a fixed order (reduceat over sorted edges)."""
    field = np.asarray(field, float)
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]).astype(np.int64)
    edges = edges[np.lexsort((edges[:, 1], edges[:, 0]))]
    starts = np.searchsorted(edges[:, 0], np.arange(len(field)))
    count = np.diff(np.append(starts, len(edges))).astype(float)
    shape = (-1,) + (1,) * (field.ndim - 1)
    for _ in range(rounds):
        field = 0.5 * field + 0.5 * np.add.reduceat(field[edges[:, 1]], starts, axis=0) / count.reshape(shape)
    return field


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
    ``joints`` (24, 3), ``weights`` (V, 24) its dense bone weights (smoothed: :func:`smoothed`), ``fractions`` the
    section heights and ``crotch`` the crotch's height (m, for its ramp; default 0.46 He)."""

    def __init__(self, vertices, joints, weights, fractions, crotch=None):
        self.rest, self.joints = np.asarray(vertices, float), np.asarray(joints, float)
        self.weights = np.asarray(weights, float)
        self.height = float(np.ptp(self.rest[:, 2]))
        z, height = self.rest[:, 2] - self.rest[:, 2].min(), self.height
        self.arm = {s: _weight(weights, [f"{s}_{j}" for j in ("Shoulder", "Elbow", "Wrist", "Hand")]) for s in SIDES}
        basis = np.zeros((len(PARAMETERS), len(self.rest), 3))
        column = {key: i for i, key in enumerate(PARAMETERS)}
        basis[column["He"], :, 2] = z
        crotch = 0.46 * height if crotch is None else crotch
        basis[column["crotch_height"], :, 2] = self._leg_stretch(z, crotch)
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
        """The trunk's horizontal scales (Hi, Wa, Br: width and depth), the shoulder girdle's widening (Sh) and the
        arms moved out with the trunk's side beside them."""
        height = self.height
        at = {key: fractions[key] * height for key in ("Hi", "Wa", "Br")}
        neck = self.joints[JOINT_INDEX["Neck"], 2] - self.rest[:, 2].min()
        shoulder = np.mean([self.joints[JOINT_INDEX[f"{s}_Shoulder"], 2] for s in SIDES]) - self.rest[:, 2].min()
        arm_any = self.arm["L"] + self.arm["R"]
        trunk = np.clip(1.0 - arm_any, 0.0, 1.0)
        front, back = self._depth_extent(z, trunk)
        knots = [at["Hi"] - HIP_FADE * height, at["Hi"], at["Wa"], at["Br"], neck]
        for k, key in enumerate(TRUNK):
            profile = trunk * cardinal(z, knots, k + 1)
            width, depth = SPLIT[key]
            pivot = front + FRONT_SHARE[key] * (back - front)  # the front moves FRONT_SHARE of the depth's change
            basis[column[key], :, 0] = profile * width * self.rest[:, 0]
            basis[column[key], :, 1] = profile * depth * (self.rest[:, 1] - pivot)
            self._arms_follow(basis[column[key]], z, trunk)
        # Sh: the arms out by the parameter (metres a side) and the shoulder girdle widened under them, its side at
        # the shoulders by GIRDLE of the arms' move, by a profile 0 at the waist rising to 1 at the shoulder joints
        # (half of it at the bust: the bank's bodies widen there by 0.23-0.33 cm per cm of Sh), 1 up to the neck
        # joint, 0 halfway up the neck; the neck and head left out by their bone weights
        head = self.weights[:, JOINT_INDEX["Neck"]] + self.weights[:, JOINT_INDEX["Head"]]
        girdle = plateau(z, at["Wa"], shoulder, neck, neck + 0.5 * (neck - shoulder))
        girdle = girdle * trunk * np.clip(1.0 - head, 0.0, 1.0)
        body = trunk > 0.5
        near = body & (np.abs(z - shoulder) <= 0.02 * height)
        half_width = float(np.abs(self.rest[near, 0]).max()) if near.any() else 0.15
        basis[column["Sh"], :, 0] = GIRDLE * girdle * self.rest[:, 0] / half_width
        for side in SIDES:
            basis[column["Sh"], :, 0] += SIDE_SIGN[side] * self.arm[side]

    def _arms_follow(self, field, z, trunk):
        """The arms moved out (x, rigidly) by the mean widening of the trunk's side beside each: ``field`` (V, 3)."""
        body = trunk > 0.5
        for side in SIDES:
            arm = self.arm[side] > 0.5
            beside = body & (SIDE_SIGN[side] * self.rest[:, 0] > 0.0)
            beside &= (z >= z[arm].min()) & (z <= self.joints[JOINT_INDEX[f"{side}_Shoulder"], 2] - 0.1)
            if not beside.any():
                continue
            slot = np.round(z[beside] / CENTRE_BIN).astype(int)
            edge = np.zeros(slot.max() + 1)
            np.maximum.at(edge, slot, SIDE_SIGN[side] * field[beside, 0])
            shift = float(edge[np.unique(slot)].mean())
            field[:, 0] += SIDE_SIGN[side] * self.arm[side] * shift

    def _depth_extent(self, z, trunk):
        """(front, back) (V,): the trunk's front and back y at each vertex's height, from the trunk's vertices'
        y extent in thin slices, smoothed."""
        kept = trunk > 0.5
        edges = np.arange(0.0, z.max() + CENTRE_BIN, CENTRE_BIN)
        slot = np.clip(np.digitize(z[kept], edges) - 1, 0, len(edges) - 2)
        y = self.rest[kept, 1]
        low = np.full(len(edges) - 1, np.inf)
        high = np.full(len(edges) - 1, -np.inf)
        np.minimum.at(low, slot, y)
        np.maximum.at(high, slot, y)
        filled = np.nonzero(np.isfinite(low))[0]
        kernel = np.ones(CENTRE_SMOOTH) / CENTRE_SMOOTH
        heights = 0.5 * (edges[1:] + edges[:-1])
        out = []
        for extent in (low, high):
            line = np.interp(np.arange(len(extent)), filled, extent[filled])
            line = np.convolve(np.pad(line, CENTRE_SMOOTH // 2, mode="edge"), kernel, mode="valid")
            out.append(np.interp(z, heights, line))
        return out

    def _joint_rings(self):
        """(24, V) each joint's share of each vertex's displacement: the vertices nearest to it."""
        offset = self.rest[None, :, :] - self.joints[:, None, :]
        distance = np.sqrt(np.einsum("jvc,jvc->jv", offset, offset))
        near = distance <= JOINT_RING * distance.min(axis=1, keepdims=True) + 1e-3
        return near / near.sum(axis=1, keepdims=True)

    def displacement(self, theta):
        """(V, 3) displacement of the vertices for parameters ``theta`` (K,)."""
        return (np.asarray(theta, float) @ self.flat).reshape(-1, 3)

    def apply(self, theta):
        """(vertices (V, 3), joints (24, 3)) of the corrected body."""
        moved = self.displacement(theta)
        return self.rest + moved, self.joints + self.ring @ moved


def abducted(vertices, joints, weights, angle):
    """(vertices, joints) with each arm raised sideways by ``angle`` (radians) about its shoulder joint (about the
    front-back axis), blended by the arm's bone weights as linear-blend skinning would: a pose, not a shape (the
    shoulder section, at the joint, hardly moves)."""
    vertices, joints = np.array(vertices, float), np.array(joints, float)
    for side in SIDES:
        shoulder = joints[JOINT_INDEX[f"{side}_Shoulder"]].copy()
        turn = -SIDE_SIGN[side] * angle  # the left arm (+X) turns about -Y to rise, the right about +Y
        c, s = np.cos(turn), np.sin(turn)
        rotation = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
        arm = _weight(weights, [f"{side}_{j}" for j in ("Shoulder", "Elbow", "Wrist", "Hand")])
        offset = vertices - shoulder
        vertices += arm[:, None] * (offset @ rotation.T - offset)
        for joint in ("Elbow", "Wrist", "Hand"):
            k = JOINT_INDEX[f"{side}_{joint}"]
            joints[k] = shoulder + (joints[k] - shoulder) @ rotation.T
    return vertices, joints
