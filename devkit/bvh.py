"""BVH clips for tests, written from scratch (no downloaded files).

A :class:`Clip` is a skeleton (bone names, parents, heads in ElliMann's axes, metres; End Sites) and per frame
each bone's rotation relative to its parent in world axes at rest (the core's pose convention, also BVH's: a
BVH rests with every joint frame along the world axes), plus the heads of the bones with position channels
(relative to the parent; the root's in the world). The file is in BVH's own axes (Y up, the character facing
+Z), in the clip's units, rotations as Euler angles in degrees in each bone's channel order (``ZXY`` is
``Zrotation Xrotation Yrotation``: R = Rz Rx Ry), as CMU's, Mixamo's and Biovision's clips are.
"""

from dataclasses import dataclass, field, replace

import numpy as np

# ElliMann (x, y, z) = TO_ELLIMANN @ BVH (x, y, z): BVH's +Z (the character's front) is ElliMann's -Y.
TO_ELLIMANN = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
SAGITTAL = np.diag([-1.0, 1.0, 1.0])
AXIS = {"X": 0, "Y": 1, "Z": 2}


@dataclass
class Clip:
    names: list
    parents: list
    heads: np.ndarray  # (k, 3) rest heads, ElliMann axes, metres
    rotations: np.ndarray  # (F, k, 3, 3) local rotations, ElliMann axes
    positions: dict  # {bone: (F, 3) its head relative to its parent (the root's: in the world)}: its position channels
    ends: dict = field(default_factory=dict)  # {bone: (3,) End Site offset from its head}
    orders: dict = field(default_factory=dict)  # {bone: 'ZXY'}; default ``order``
    order: str = "ZXY"
    unit: float = 0.01  # metres per file unit
    frame_time: float = 1.0 / 24.0
    twins: list = None  # each bone's mirror twin (its index), for mirrored()

    @property
    def frames(self):
        return len(self.rotations)

    def world(self):
        """(F, k, 3, 3) world rotations and (F, k, 3) heads of the clip (ElliMann axes, metres)."""
        frames, count = self.rotations.shape[:2]
        world, heads = np.empty_like(self.rotations), np.empty((frames, count, 3))
        for i, parent in enumerate(self.parents):
            offset = self.positions.get(i)
            if offset is None:
                offset = np.broadcast_to(self.heads[i] - (self.heads[parent] if parent >= 0 else 0.0), (frames, 3))
            if parent < 0:
                world[:, i], heads[:, i] = self.rotations[:, i], offset
            else:
                world[:, i] = world[:, parent] @ self.rotations[:, i]
                heads[:, i] = heads[:, parent] + np.einsum("fij,fj->fi", world[:, parent], offset)
        return world, heads


def euler_degrees(rotation, order):
    """Angles (degrees) in channel ``order`` (e.g. 'ZXY') with rotation = R_first(a) R_second(b) R_third(c)."""
    i, j, k = (AXIS[a] for a in order)
    r = np.asarray(rotation, float)
    sign = 1.0 if (j - i) % 3 == 1 else -1.0  # XYZ, YZX, ZXY are cyclic
    b = np.arcsin(np.clip(sign * r[i, k], -1.0, 1.0))
    a = np.arctan2(-sign * r[j, k], r[k, k])
    c = np.arctan2(-sign * r[i, j], r[i, i])
    return np.degrees([a, b, c])


def axis_rotation(axis, degrees):
    """The rotation about unit ``axis`` (3,) by ``degrees``."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    angle = np.radians(degrees)
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * k @ k


def rotation_x(degrees):
    return axis_rotation([1.0, 0.0, 0.0], degrees)


def rotation_y(degrees):
    return axis_rotation([0.0, 1.0, 0.0], degrees)


def rotation_z(degrees):
    return axis_rotation([0.0, 0.0, 1.0], degrees)


def write_bvh(path, clip):
    """Write ``clip`` as a BVH file; returns the path."""
    to_bvh = TO_ELLIMANN.T
    scale = 1.0 / clip.unit
    children = {i: [j for j, p in enumerate(clip.parents) if p == i] for i in range(len(clip.names))}
    lines, order = ["HIERARCHY"], []

    def numbers(values):
        return " ".join(f"{v:.6f}" for v in values)

    def joint(i, depth):
        pad, parent = "  " * depth, clip.parents[i]
        order.append(i)
        offset = clip.heads[i] - (clip.heads[parent] if parent >= 0 else 0.0)
        lines.append(f"{pad}{'ROOT' if parent < 0 else 'JOINT'} {clip.names[i]}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}  OFFSET {numbers(to_bvh @ offset * scale)}")
        rotations = " ".join(f"{a}rotation" for a in clip.orders.get(i, clip.order))
        channels = f"6 Xposition Yposition Zposition {rotations}" if i in clip.positions else f"3 {rotations}"
        lines.append(f"{pad}  CHANNELS {channels}")
        for child in children[i]:
            joint(child, depth + 1)
        if i in clip.ends:
            end = numbers(to_bvh @ clip.ends[i] * scale)
            lines.extend([f"{pad}  End Site", f"{pad}  {{", f"{pad}    OFFSET {end}", f"{pad}  }}"])
        lines.append(f"{pad}}}")

    for root in [i for i, p in enumerate(clip.parents) if p < 0]:
        joint(root, 0)
    lines += ["MOTION", f"Frames: {clip.frames}", f"Frame Time: {clip.frame_time:.6f}"]
    for frame in range(clip.frames):
        values = []
        for i in order:
            if i in clip.positions:
                values += list(to_bvh @ clip.positions[i][frame] * scale)
            values += list(
                euler_degrees(to_bvh @ clip.rotations[frame, i] @ TO_ELLIMANN, clip.orders.get(i, clip.order))
            )
        lines.append(numbers(values))
    with open(path, "w", encoding="utf-8") as stream:
        stream.write("\n".join(lines) + "\n")
    return path


def mirrored(clip):
    """The clip's mirror image across x = 0 on its own (symmetric) skeleton: each bone does what its twin did,
    mirrored (M R M), the positions' x negated."""
    twins = clip.twins
    rotations = SAGITTAL @ clip.rotations[:, twins] @ SAGITTAL
    positions = {i: clip.positions[twins[i]] * [-1.0, 1.0, 1.0] for i in clip.positions}
    return replace(clip, rotations=rotations, positions=positions)
