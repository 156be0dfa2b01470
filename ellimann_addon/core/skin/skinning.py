"""A skin's bone weights for linear-blend skinning (what glTF and Blender's Armature modifier apply): each joint
bends the skin smoothly across a blend plane of its own, and the skin keeps its volume when the legs bend.

Not the bones of the pieces a vertex follows: pieces do not end at joints (a knee piece rides on the thigh's bone
and reaches 20 cm down the shin), so such weights bend the shin with the thigh and fold the calf over it.

The joints decide. Joint c (between bone p = PARENTS[c] and bone c) has a blend plane through o_c, normal n_c into
c's side, and a half-width h_c: bone c's share across it is rho_c(x) = S((x - o_c).n_c / 2 h_c + 1/2), S the
smoothstep. n_c bisects the parent's and the child's directions (the child's alone where the parent branches: the
hips, the spine, the neck, the collars); h_c is WIDTH times the joint's depth inside its pieces, at most CAP of the
shorter bone beside it. The pieces only tell where in the skeleton a vertex lies: it follows pieces k with weights
pi_k (``core.skin.weights.piece_weights``); a piece on bone b offers b, its parent and its children (and the bones
beyond one no piece rides on, as Spine3), shared along that small tree by the ramps (a child takes rho_c of its
parent's share, the parent keeps 1 - rho_c); a limb leaving a central bone (a hip, a collar) reaches a central
piece's vertices only on its own side, faded in from the sagittal plane to its joint. A vertex's weights are
sum_k pi_k D_k(x), the INFLUENCES largest kept: continuous wherever the piece weights are, and where its nearest
piece changes too (pieces beside one joint share out the same ramp).

Volume. Bending one joint by theta about an axis a through it changes the skinned volume by exactly

    dV = -(1 - cos theta) * integral of w (1 - w) (r_perp . N) dS  +  sin theta * integral of w (a x r) . N dS

over the skin (w the bent side's weight, r = x - joint, r_perp its part across a, N the outward normal: the
divergence theorem on the blended map; ``tests/core/skin/test_skinning.py`` checks it). The first term always loses,
the more the wider the blend; the second depends only on where the blend runs round the limb. The hips lose most:
the thigh's flesh lies in front of the hip joint, so a blend at the joint's level folds the thigh into the belly
when it flexes. So the hips bend lower, their planes HIP_DROP of the way from the joint down to the lowest point of
the pelvis's pieces (where the thighs leave the trunk), over HIP_WIDEN times the width (the buttocks round, not
creased, when sitting), and both are tilted about world X by the smallest angle (within MAX_TILT) at which the skin
keeps its volume with the hips and knees flexed 90 degrees (sit's bend): front higher, back lower, as a body's groin
and gluteal folds run. The search is on the posed mesh's volume, outward from no tilt, then regula falsi.
"""

from dataclasses import dataclass

import numpy as np

from ..geometry.ellipsoid import bounds
from ..geometry.mesh import directed_edges, volume
from ..mannequin.skeleton import CHILDREN, JOINT_COUNT, JOINT_INDEX, JOINT_NAMES, PARENTS, part_bones
from ..pose.kinematics import Pose, axis_angle, bone_matrices, require_joints
from .field import piece_distance
from .weights import INFLUENCES, follow_pieces

WIDTH = 0.8  # a joint's blend half-width, times the joint's depth inside its pieces
CAP = 0.5  # ... and at most this share of the shorter bone beside the joint
MIN_DEPTH = 0.01  # m: the depth used for a joint that lies (nearly) outside its pieces
HIP_DROP = 0.75  # the hips' planes: this share of the way from the joint down to the pelvis's lowest point
HIP_WIDEN = 1.6  # ... over this many times the width
BALANCED = ("L_Hip", "R_Hip")  # tilted alike so that the skin keeps its volume in BENT
BENT = {"L_Hip": -90.0, "R_Hip": -90.0, "L_Knee": 90.0, "R_Knee": 90.0}  # degrees about world X: sitting
MAX_TILT = np.radians(45.0)
TILT_STEP = np.radians(7.5)  # the searches' first step from no tilt
SECANT_STEPS = 8
TOLERANCE = 2e-4  # of the volume: a tilt that keeps it this well is found
CREASE_JUMP = 0.9  # summed weight change along one edge that marks a crease
CREASE_WIDTH = 0.02  # m: how far from a crease its weights are smoothed
SIDED = {"L": 1.0, "R": -1.0}  # which way of the sagittal plane a side lies
_X = np.array([1.0, 0.0, 0.0])


@dataclass(frozen=True)
class Ramps:
    """Each joint's blend plane (through ``origin`` (24, 3), normal ``normal`` (24, 3) into the child's side) and
    half-width ``half`` (24,) m; row 0 (the root) unused."""

    origin: np.ndarray
    normal: np.ndarray
    half: np.ndarray

    def tilted(self, joints, angle):
        """These ramps with the planes of ``joints`` turned by ``angle`` about world X through their origins."""
        normal = self.normal.copy()
        normal[joints] = normal[joints] @ axis_angle(_X, angle).T
        return Ramps(self.origin, normal, self.half)


def _unit(vector):
    return vector / np.linalg.norm(vector)


def _main_child(bone):
    """The child that carries ``bone`` on: the central one where it branches (the spine, the neck)."""
    kids = CHILDREN[bone]
    central = [k for k in kids if JOINT_NAMES[k][:2] not in ("L_", "R_")]
    return (central or list(kids))[0]


def _direction(joints, bone):
    """Bone's direction: from its joint to its main child's (a leaf continues its parent's)."""
    if not CHILDREN[bone]:
        return _unit(joints[bone] - joints[PARENTS[bone]])
    return _unit(joints[_main_child(bone)] - joints[bone])


def joint_ramps(mannequin, bones):
    """The blend planes and half-widths (:class:`Ramps`) of a mannequin with joints; ``bones``: each part's bone."""
    joints = np.asarray(mannequin.joints, dtype=float)
    arrays = (mannequin.rotation, mannequin.center, mannequin.semi_axes)
    origin, normal, half = joints.copy(), np.zeros((JOINT_COUNT, 3)), np.ones(JOINT_COUNT)
    for c in range(1, JOINT_COUNT):
        p = PARENTS[c]
        child = _direction(joints, c)
        if len(CHILDREN[p]) > 1:
            normal[c] = child
        else:
            both = _unit(joints[c] - joints[p]) + child
            normal[c] = _unit(both) if np.linalg.norm(both) > 1e-6 else child
        near = np.flatnonzero((bones == p) | (bones == c))
        near = near if len(near) else np.arange(len(bones))
        depth = -min(float(piece_distance(joints[c][None], *(a[i] for a in arrays))[0]) for i in near)
        lengths = [np.linalg.norm(joints[c] - joints[p])] + [np.linalg.norm(joints[k] - joints[c]) for k in CHILDREN[c]]
        half[c] = min(WIDTH * max(depth, MIN_DEPTH), CAP * min(lengths))
    pelvis = bones == 0
    if pelvis.any():  # the hips bend where the thighs leave the trunk, not at the joint's level
        lowest = bounds(*(a[pelvis] for a in arrays))[0][:, 2].min()
        for name in BALANCED:
            c = JOINT_INDEX[name]
            drop = HIP_DROP * max(joints[c, 2] - lowest, 0.0)
            origin[c] = joints[c] + normal[c] * drop / max(-normal[c, 2], 0.5)
            half[c] *= HIP_WIDEN
    return Ramps(origin, normal, half)


def _smoothstep(t):
    t = np.clip(t, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def ramp_values(points, ramps, joints):
    """rho (len(points), 24): each joint's child share at ``points``; and the side fade (len(points), 24) of the
    limbs leaving a central bone (1 elsewhere), for central pieces."""
    rho = _smoothstep(
        (points @ ramps.normal.T - np.einsum("ij,ij->i", ramps.origin, ramps.normal)) / (2.0 * ramps.half) + 0.5
    )
    fade = np.ones_like(rho)
    for c in LEAVING:
        fade[:, c] = _smoothstep(SIDED[JOINT_NAMES[c][0]] * points[:, 0] / max(abs(joints[c, 0]), MIN_DEPTH))
    return rho, fade


def _leaving():
    """The joints where a left or right limb leaves a central bone (the hips, the collars)."""
    sided = [c for c in range(1, JOINT_COUNT) if JOINT_NAMES[c][:2] in ("L_", "R_")]
    return tuple(c for c in sided if JOINT_NAMES[PARENTS[c]][:2] not in ("L_", "R_"))


LEAVING = _leaving()


class _Group:
    """The pieces of one bone and side: the bones they offer (a small tree from ``top``), each bone's path of joints
    from the top and its children in the tree."""

    def __init__(self, bone, side, has_pieces):
        offered = {bone}
        p = PARENTS[bone]
        if p >= 0:
            offered.add(p)
            if p not in has_pieces and PARENTS[p] >= 0:
                offered.add(PARENTS[p])
        for c in CHILDREN[bone]:
            offered.add(c)
            if c not in has_pieces:
                offered.update(CHILDREN[c])
        self.bones = sorted(offered)
        top = next(u for u in self.bones if PARENTS[u] not in offered)
        self.joints = [u for u in self.bones if u != top]  # the joints whose ramps share this group out
        self.paths, self.kids = [], []
        for u in self.bones:
            path, v = [], u
            while v != top:
                path.append(v)
                v = PARENTS[v]
            self.paths.append(path)
            self.kids.append([c for c in CHILDREN[u] if c in offered])
        # a limb leaving a central bone: faded in across the sagittal plane for central pieces, never for the
        # other side's
        self.scale = np.ones(JOINT_COUNT)
        for c in LEAVING:
            if side != "C" and SIDED[side] != SIDED[JOINT_NAMES[c][0]]:
                self.scale[c] = 0.0
        self.faded = side == "C"

    def shares(self, rho, fade):
        """(k, len(self.bones)): how the group's weight is shared among its bones at k points, from their ramp
        values and side fades (k, 24) (:func:`ramp_values`)."""
        rho = rho * self.scale * (fade if self.faded else 1.0)
        out = np.empty((len(rho), len(self.bones)))
        for k, (path, kids) in enumerate(zip(self.paths, self.kids)):
            share = np.ones(len(rho))
            for c in path:
                share = share * rho[:, c]
            for c in kids:
                share = share * (1.0 - rho[:, c])
            out[:, k] = share
        return out / out.sum(axis=1, keepdims=True)


class _Blend:
    """The vertices' bone weights (dense (V, 24)) as the sum of every group's part, kept per group so that tilting
    one joint redoes only the groups whose ramps include it."""

    def __init__(self, vertices, groups, group_weights, ramps, joints):
        self.vertices, self.groups, self.joints = vertices, groups, joints
        self.rho, self.fade = ramp_values(vertices, ramps, joints)
        self.rows = [np.flatnonzero(group_weights[:, g] > 0.0) for g in range(len(groups))]
        self.weight = [group_weights[rows, g] for g, rows in enumerate(self.rows)]
        self.dense = np.zeros((len(vertices), JOINT_COUNT))
        self.parts = []
        for g, (group, rows) in enumerate(zip(groups, self.rows)):
            self.parts.append(self.weight[g][:, None] * group.shares(self.rho[rows], self.fade[rows]))
            self.dense[rows[:, None], group.bones] += self.parts[g]

    def using(self, joints):
        """The groups whose ramps include one of ``joints``."""
        return [g for g, group in enumerate(self.groups) if set(joints) & set(group.joints)]

    def tilt(self, joints, ramps):
        """The parts {group: part} of the groups that use ``joints``, with their ramps from ``ramps``."""
        changed = {}
        for g in self.using(joints):
            rows = self.rows[g]
            rho = self.rho[rows].copy()
            for joint in joints:
                rho[:, joint] = _ramp_column(self.vertices[rows], ramps, joint)
            changed[g] = self.weight[g][:, None] * self.groups[g].shares(rho, self.fade[rows])
        return changed

    def dense_with(self, changed, rows):
        """The dense weights of the vertices ``rows`` (ascending) with the ``changed`` parts (:meth:`tilt`)."""
        dense = self.dense[rows]
        for g, part in changed.items():
            at = np.searchsorted(rows, self.rows[g])  # every changed group's rows lie within ``rows``
            dense[at[:, None], self.groups[g].bones] += part - self.parts[g]
        return dense

    def keep(self, joints, ramps, changed):
        """Take the changed parts for good (the ramps of ``joints`` now those of ``ramps``)."""
        for joint in joints:
            self.rho[:, joint] = _ramp_column(self.vertices, ramps, joint)
        for g, part in changed.items():
            rows, bones = self.rows[g], self.groups[g].bones
            self.dense[rows[:, None], bones] += part - self.parts[g]
            self.parts[g] = part


def _ramp_column(points, ramps, joint):
    return _smoothstep(((points - ramps.origin[joint]) @ ramps.normal[joint]) / (2.0 * ramps.half[joint]) + 0.5)


def skinning_weights(vertices, faces, pieces, weights, mannequin):
    """(bones (V, 4) SMPL joint indices, weights (V, 4), largest first; unused slots bone 0 with weight 0) of a
    skin's vertices, faces and piece weights (``core.skin.weights.piece_weights``) on ``mannequin`` (with joints:
    ElliMannError otherwise)."""
    joints = require_joints(mannequin)
    bones = part_bones(mannequin.topology)
    ramps = joint_ramps(mannequin, bones)
    has_pieces = set(bones.tolist())
    keys = sorted({(int(b), part.side) for b, part in zip(bones, mannequin.topology)})
    groups = [_Group(b, side, has_pieces) for b, side in keys]
    group_of = np.array([keys.index((int(b), part.side)) for b, part in zip(bones, mannequin.topology)])
    flat = (np.arange(len(vertices))[:, None] * len(groups) + group_of[pieces]).ravel()
    group_weights = np.bincount(flat, weights.ravel(), len(vertices) * len(groups)).reshape(len(vertices), -1)
    blend = _Blend(vertices, groups, group_weights, ramps, joints)
    _balance(blend, ramps, [JOINT_INDEX[name] for name in BALANCED], faces)
    return largest(smooth_creases(blend.dense, vertices, faces))


def smooth_creases(dense, vertices, faces):
    """Dense weights (V, 24) smoothed across creases: where two parts that do not blend touch (the arm at the
    armpit, the thighs at the crotch), one edge can hold a vertex of each, and a posed limb would stretch that one
    edge into a web. Around every edge whose two ends' weights differ by more than CREASE_JUMP (summed over the
    bones), the weights are averaged with the neighbours' over CREASE_WIDTH (Jacobi steps on the mesh, a step per
    edge length): the stretch is shared by the faces there."""
    edges = directed_edges(faces)
    edges = edges[edges[:, 0] < edges[:, 1]]  # a closed 2-manifold: each edge once
    top = np.argmax(dense, axis=1)
    changing = edges[top[edges[:, 0]] != top[edges[:, 1]]]  # a jump changes the largest bone: only those are tested
    jump = changing[np.abs(dense[changing[:, 0]] - dense[changing[:, 1]]).sum(axis=1) > CREASE_JUMP]
    if len(jump) == 0:
        return dense
    length = np.linalg.norm(vertices[edges[:, 0]] - vertices[edges[:, 1]], axis=1).mean()
    steps = max(1, int(np.ceil(CREASE_WIDTH / length)))
    band = np.zeros(len(vertices), dtype=bool)
    band[jump.ravel()] = True
    for _ in range(steps):  # the band: every vertex within ``steps`` edges of a crease
        band[edges[band[edges].any(axis=1)].ravel()] = True
    rows = np.flatnonzero(band)
    inner = np.searchsorted(rows, edges[band[edges].all(axis=1)])
    # each band vertex's neighbours in the band, itself first, grouped by vertex (for np.add.reduceat)
    source = np.concatenate([np.arange(len(rows)), inner[:, 0], inner[:, 1]])
    target = np.concatenate([np.arange(len(rows)), inner[:, 1], inner[:, 0]])
    order = np.argsort(source, kind="stable")
    starts = np.searchsorted(source[order], np.arange(len(rows)))
    neighbours = target[order]
    count = np.diff(np.append(starts, len(order)))[:, None]
    smoothed = dense.copy()
    used = np.flatnonzero(dense[rows].any(axis=0))  # the bones the band holds
    local = dense[rows[:, None], used]
    for _ in range(steps * steps):  # a diffusion's reach grows as the square root of its steps
        local = np.add.reduceat(local[neighbours], starts, axis=0) / count
    smoothed[rows[:, None], used] = local
    return smoothed


def largest(dense):
    """(bones (V, INFLUENCES), weights (V, INFLUENCES)): the largest of dense weights (V, 24), normalised, largest
    first (unused slots: bone 0, weight 0)."""
    keep = np.argsort(-dense, axis=1, kind="stable")[:, :INFLUENCES]
    kept = np.take_along_axis(dense, keep, axis=1)
    return np.where(kept > 0.0, keep, 0), kept / kept.sum(axis=1, keepdims=True)


def bent_pose():
    """The pose the hips are balanced in: hips and knees flexed 90 degrees about world X (sit, without its splay)."""
    rotations = np.repeat(np.eye(3)[None], JOINT_COUNT, axis=0)
    for name, degrees in BENT.items():
        rotations[JOINT_INDEX[name]] = axis_angle(_X, np.radians(degrees))
    return Pose(rotations)


def _balance(blend, ramps, joints, faces):
    """Tilt the planes of ``joints`` alike to the smallest angle within MAX_TILT at which the skin keeps its volume
    in :func:`bent_pose` (or the best angle tried), updating ``blend``; returns the ramps with that tilt."""
    matrices = bone_matrices(blend.joints, bent_pose())[:, :3, :]
    moving = np.flatnonzero(np.abs(matrices - np.eye(4)[:3]).max(axis=(1, 2)) > 0.0)
    touched = blend.dense[:, moving].any(axis=1)  # the vertices that may move: weighted to a bone that turns
    for g in blend.using(joints):
        touched[blend.rows[g]] = True
    rows = np.flatnonzero(touched)
    if len(rows) == 0:
        return ramps
    vertices = blend.vertices
    near = faces[touched[faces].any(axis=1)]  # the other faces do not move: their share of the volume stays
    rest, total = volume(vertices, near), volume(vertices, faces)
    tried = {}

    def change(angle):
        if angle not in tried:
            tilted = ramps.tilted(joints, angle)
            changed = blend.tilt(joints, tilted)
            moved = vertices.copy()
            moved[rows] = follow_pieces(vertices[rows], *largest(blend.dense_with(changed, rows)), matrices)
            tried[angle] = ((volume(moved, near) - rest) / total, tilted, changed)
        return tried[angle][0]

    _, tilted, changed = tried[_root(change)]
    blend.keep(joints, tilted, changed)
    return tilted


def _root(change):
    """A zero of ``change`` (of the tilt angle) within MAX_TILT by the secant method from no tilt, or, if that does
    not converge, the best of a scan outward from no tilt refined by regula falsi."""
    a, fa = 0.0, change(0.0)
    b, fb = TILT_STEP, change(TILT_STEP)
    for _ in range(SECANT_STEPS):
        if abs(fb) <= TOLERANCE:
            return b
        if fb == fa:
            break
        a, fa, b = b, fb, float(np.clip(b - fb * (b - a) / (fb - fa), -MAX_TILT, MAX_TILT))
        fb = change(b)
    if abs(fb) <= TOLERANCE:
        return b
    return _scanned_root(change)


def _scanned_root(change):
    """The zero of ``change`` nearest no tilt (within MAX_TILT), or the tried angle of least |change|."""
    start = change(0.0)
    tried, bracket = [0.0], None
    for step in np.arange(TILT_STEP, MAX_TILT + 1e-9, TILT_STEP):
        for angle in (step, -step):
            tried.append(angle)
            if np.sign(change(angle)) != np.sign(start):
                bracket = (np.sign(angle) * (step - TILT_STEP), angle)
                break
        if bracket:
            break
    if bracket is None:
        return min(tried, key=lambda angle: abs(change(angle)))
    (a, b), side = bracket, 0
    fa, fb = change(a), change(b)
    for _ in range(SECANT_STEPS):  # regula falsi, Illinois
        c = (fa * b - fb * a) / (fa - fb)
        fc = change(c)
        if abs(fc) <= TOLERANCE:
            return c
        if np.sign(fc) == np.sign(fb):
            b, fb = c, fc
            fa = fa / 2.0 if side == -1 else fa
            side = -1
        else:
            a, fa = c, fc
            fb = fb / 2.0 if side == 1 else fb
            side = 1
    return min((a, b), key=lambda angle: abs(change(angle)))
