"""Unit quaternions (w, x, y, z) <-> rotation matrices, batched over leading dimensions.

The order is MuJoCo's and glTF's scalar position differs (glTF stores x, y, z, w); callers reorder.
Matrix -> quaternion uses Shepperd's method: of the four equivalent formulas it takes the one
whose divisor (4w, 4x, 4y or 4z) is largest, so no precision is lost near 180-degree turns where
the trace formula divides by almost zero.
"""

import numpy as np


def rotation_to_quaternion(rotation):
    """(..., 3, 3) rotations -> (..., 4) unit quaternions (w, x, y, z) with w >= 0.

    A slightly non-orthonormal input gives the quaternion of a nearby rotation (the result is
    normalised); q and -q are the same rotation, so w >= 0 makes the result unique except at w = 0.
    """
    r = np.asarray(rotation, dtype=float)
    m00, m01, m02 = r[..., 0, 0], r[..., 0, 1], r[..., 0, 2]
    m10, m11, m12 = r[..., 1, 0], r[..., 1, 1], r[..., 1, 2]
    m20, m21, m22 = r[..., 2, 0], r[..., 2, 1], r[..., 2, 2]
    # Each row is 4 * q_k * q for one k in (w, x, y, z); the diagonal entries are 4 q_k^2.
    candidates = np.stack(
        [
            np.stack([1.0 + m00 + m11 + m22, m21 - m12, m02 - m20, m10 - m01], axis=-1),
            np.stack([m21 - m12, 1.0 + m00 - m11 - m22, m01 + m10, m02 + m20], axis=-1),
            np.stack([m02 - m20, m01 + m10, 1.0 - m00 + m11 - m22, m12 + m21], axis=-1),
            np.stack([m10 - m01, m02 + m20, m12 + m21, 1.0 - m00 - m11 + m22], axis=-1),
        ],
        axis=-2,
    )
    diagonal = np.stack([candidates[..., k, k] for k in range(4)], axis=-1)
    best = np.argmax(diagonal, axis=-1)
    q = np.take_along_axis(candidates, best[..., None, None], axis=-2)[..., 0, :]
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0.0, -q, q)


def quaternion_to_rotation(quaternion):
    """(..., 4) quaternions (w, x, y, z), any non-zero length -> (..., 3, 3) rotations."""
    q = np.asarray(quaternion, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=-2,
    )
