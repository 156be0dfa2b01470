"""Ellipsoids as frames and semi-axes, in closed form and vectorised.

An ellipsoid is {c + R diag(D) s : |s| <= 1}: centre ``c`` (3,), rotation ``R`` (3, 3) in SO(3)
whose columns are the local axes, and semi-axes ``D`` (3,) > 0 along those axes. Every function
here broadcasts over leading dimensions, so a whole mannequin (n, ...) or a batch of mannequins
(B, n, ...) goes through one call.
"""

from dataclasses import dataclass

import numpy as np

from ..errors import FrameError
from .frames import mirror_axis, project_to_rotation, relabel_to_reference, rigid_matrix

ORTHONORMAL_TOL = 1e-6


def shape_matrix(rotation, semi_axes):
    """M = R diag(D^2) R^T: the ellipsoid is {x : (x-c)^T M^-1 (x-c) <= 1}."""
    scaled = rotation * (np.asarray(semi_axes)[..., None, :] ** 2)
    return scaled @ np.swapaxes(rotation, -1, -2)


def linear_image(rotation, semi_axes, matrix):
    """The ellipsoid mapped by a linear map A (3, 3), invertible, about its centre (move the centre by A
    yourself): (rotation, semi_axes) of {A x : x in E}, shape A M A^T, its axes labelled as the original's
    nearest (relabel_to_reference), so that a map near the identity keeps each axis its name. Stacks (..., 3, 3)."""
    values, vectors = np.linalg.eigh(matrix @ shape_matrix(rotation, semi_axes) @ np.swapaxes(matrix, -1, -2))
    vectors[..., :, 2] *= np.sign(np.linalg.det(vectors))[..., None]  # proper: an orthonormal det is +-1
    new_rotation, new_semi_axes, _ = relabel_to_reference(vectors, np.sqrt(values), rotation)
    return new_rotation, new_semi_axes


def support_and_point(rotation, center, semi_axes, directions):
    """Support function h(n) = c.n + sqrt(n^T M n) and support point c + M n / sqrt(n^T M n), the
    boundary point where the plane with outward normal n touches the ellipsoid.

    ``directions`` (..., V, 3), unit or not, broadcast against the ellipsoids' leading dimensions;
    returns (h (..., V), points (..., V, 3)).
    """
    directions = np.asarray(directions, dtype=float)
    center = np.asarray(center, dtype=float)
    mn = directions @ shape_matrix(np.asarray(rotation, dtype=float), np.asarray(semi_axes, dtype=float))
    root = np.sqrt(np.einsum("...i,...i->...", directions, mn))  # M is symmetric: rows of mn are M n
    return (directions @ center[..., :, None])[..., 0] + root, center[..., None, :] + mn / root[..., None]


def support(rotation, center, semi_axes, direction):
    """Support function h(n) for directions (..., 3) broadcast against the ellipsoids: (...)."""
    one_each = np.asarray(direction, dtype=float)[..., None, :]
    return support_and_point(rotation, center, semi_axes, one_each)[0][..., 0]


def support_point(rotation, center, semi_axes, direction):
    """Support point for directions (..., 3) broadcast against the ellipsoids: (..., 3)."""
    one_each = np.asarray(direction, dtype=float)[..., None, :]
    return support_and_point(rotation, center, semi_axes, one_each)[1][..., 0, :]


def axis_extent(rotation, semi_axes, axis):
    """Half-width of the ellipsoid along world axis 0, 1 or 2: sqrt(M[axis, axis])."""
    r = np.asarray(rotation)[..., axis, :]
    return np.sqrt(np.sum((r * semi_axes) ** 2, axis=-1))


def bounds(rotation, center, semi_axes):
    """Axis-aligned bounding box (lo, hi), each (..., 3)."""
    half = np.stack([axis_extent(rotation, semi_axes, axis) for axis in range(3)], axis=-1)
    return center - half, center + half


def _shape_entry(r, d2, i, j):
    """M[i, j] of the shape matrix from R and D^2, in a fixed order (a mannequin gets the same bits alone as in a
    batch)."""
    return (
        r[..., i, 0] * r[..., j, 0] * d2[..., 0]
        + r[..., i, 1] * r[..., j, 1] * d2[..., 1]
        + r[..., i, 2] * r[..., j, 2] * d2[..., 2]
    )


def section_shape(rotation, semi_axes):
    """What every horizontal section of an ellipsoid shares: (M_zz (...), m = M[:2, 2] / M_zz (..., 2), the Schur
    complement M_xy - m m^T M_zz (..., 2, 2)), M the shape matrix, entry by entry in a fixed order (a mannequin
    gets the same bits alone as in a batch)."""
    r = np.asarray(rotation, dtype=float)
    d2 = np.asarray(semi_axes, dtype=float) ** 2

    def entry(i, j):
        return _shape_entry(r, d2, i, j)

    mzz = entry(2, 2)
    slope = np.stack([entry(0, 2), entry(1, 2)], axis=-1) / mzz[..., None]
    xy = entry(0, 1) - slope[..., 0] * slope[..., 1] * mzz
    schur = np.stack(
        [
            np.stack([entry(0, 0) - slope[..., 0] ** 2 * mzz, xy], axis=-1),
            np.stack([xy, entry(1, 1) - slope[..., 1] ** 2 * mzz], axis=-1),
        ],
        axis=-2,
    )
    return mzz, slope, schur


def section_at_height(rotation, center, semi_axes, height, shape=None):
    """Horizontal section z = height of each ellipsoid, in closed form.

    A plane section of an ellipsoid is an ellipse {u : (u - c2)^T K^-1 (u - c2) <= 1} in (x, y).
    With M the shape matrix, m = M[:2, 2], dz = height - c_z:
        c2 = c_xy + dz m / M_zz,   K = (1 - dz^2 / M_zz) (M_xy - m m^T / M_zz).
    ``shape``: :func:`section_shape` of the ellipsoids when it is at hand (several heights).
    Returns (centre (..., 2), K (..., 2, 2), hit (...)); hit is False where the plane misses.
    """
    mzz, slope, schur = section_shape(rotation, semi_axes) if shape is None else shape
    dz = np.asarray(height) - center[..., 2]
    shrink = 1.0 - dz * dz / mzz
    hit = shrink > 0.0
    centre2 = center[..., :2] + dz[..., None] * slope
    k = np.clip(shrink, 0.0, None)[..., None, None] * schur
    return centre2, k, hit


def section_extent(rotation, center, semi_axes, height, axis):
    """Middle and half-width along world x (``axis`` 0) or y (1) of each horizontal section z = height, and hit:
    :func:`section_at_height`'s centre[..., axis], sqrt(K[axis, axis]) and hit, the same bits, without the rest."""
    r = np.asarray(rotation, dtype=float)
    d2 = np.asarray(semi_axes, dtype=float) ** 2
    mzz = _shape_entry(r, d2, 2, 2)
    slope = _shape_entry(r, d2, axis, 2) / mzz
    schur = _shape_entry(r, d2, axis, axis) - slope**2 * mzz
    dz = np.asarray(height) - center[..., 2]
    shrink = 1.0 - dz * dz / mzz
    return center[..., axis] + dz * slope, np.sqrt(np.clip(shrink, 0.0, None) * schur), shrink > 0.0


def sample_surface(rotation, center, semi_axes, count=256):
    """Quasi-uniform points on the surface (Fibonacci sphere mapped through R diag(D)); (..., count, 3)."""
    unit = fibonacci_sphere(count)
    local = unit * np.asarray(semi_axes)[..., None, :]
    return np.einsum("...ij,...kj->...ki", rotation, local) + np.asarray(center)[..., None, :]


def fibonacci_sphere(count):
    """``count`` nearly uniform unit vectors (golden-angle spiral)."""
    i = np.arange(count) + 0.5
    z = 1.0 - 2.0 * i / count
    r = np.sqrt(np.clip(1.0 - z * z, 0.0, None))
    phi = np.pi * (3.0 - np.sqrt(5.0)) * i
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


def to_frame(points, origin, rotation):
    """Points (p, 3) in the frame ``rotation`` (3, 3) (its columns the axes) about ``origin``: (points - origin) @
    rotation, by einsum: as a BLAS product a long (p, 3) array starts OpenBLAS's threads, which then spin on the
    cores a parallel build's other processes are using (a body's fit took 30-32 s of CPU instead of 20-21 s)."""
    return np.einsum("pj,jk->pk", np.asarray(points) - origin, rotation)


def contains(rotation, center, semi_axes, points, tol=0.0):
    """True where a point lies inside (or within ``tol`` of the unit level set of) the ellipsoid."""
    local = np.einsum("...ji,...j->...i", rotation, np.asarray(points) - center) / semi_axes
    return np.sum(local * local, axis=-1) <= 1.0 + tol


def volume(semi_axes):
    return 4.0 / 3.0 * np.pi * np.prod(semi_axes, axis=-1)


def matrix_world(rotation, center, semi_axes):
    """Blender's object matrix for an ellipsoid on a unit-sphere mesh: S @ diag(D, 1)."""
    return rigid_matrix(np.asarray(rotation, dtype=float) * np.asarray(semi_axes)[..., None, :], center)


def decompose_matrix_world(matrix, tol=ORTHONORMAL_TOL):
    """Inverse of :func:`matrix_world` for one 4x4 matrix; refuses what is not an ellipsoid frame.

    Raises FrameError naming the problem: zero scale, shear (axes not orthogonal) or a
    left-handed frame (negative scale). Returns (rotation, center, semi_axes).
    """
    matrix = np.asarray(matrix, dtype=float)
    if matrix.shape != (4, 4) or not np.all(np.isfinite(matrix)):
        raise FrameError("matrix", "must be a finite 4x4 matrix")
    if not np.allclose(matrix[3], (0.0, 0.0, 0.0, 1.0), atol=tol):
        raise FrameError("matrix", "has a projective part; expected an affine object matrix")
    linear = matrix[:3, :3]
    semi_axes = np.linalg.norm(linear, axis=0)
    if np.any(semi_axes <= 1e-12):
        raise FrameError("scale", f"has a zero axis: semi-axes {semi_axes.tolist()}", "zero")
    rotation = linear / semi_axes
    if not np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-4):
        raise FrameError(
            "rotation",
            "is sheared: the local axes are not orthogonal (apply rotation/scale "
            "of a parent, or rebuild the ellipsoid)",
            "shear",
        )
    if np.linalg.det(rotation) < 0.0:
        raise FrameError("rotation", "is left-handed (a negative scale); flip one axis to fix it", "negative")
    return rotation, matrix[:3, 3].copy(), semi_axes


def decompose_matrices_world(matrices, tol=ORTHONORMAL_TOL):
    """:func:`decompose_matrix_world` of a stack (n, 4, 4) in one vectorised pass: stacked
    (rotation, center, semi_axes), the same numbers as one call per matrix, or None when any matrix
    is not an ellipsoid frame (decompose them one by one to learn which and why).
    """
    matrices = np.asarray(matrices, dtype=float).reshape(-1, 4, 4)
    if not np.all(np.isfinite(matrices)) or not np.allclose(matrices[:, 3], (0.0, 0.0, 0.0, 1.0), atol=tol):
        return None
    linear = matrices[:, :3, :3]
    semi_axes = np.linalg.norm(linear, axis=1)
    if np.any(semi_axes <= 1e-12):
        return None
    rotation = linear / semi_axes[:, None, :]
    gram = np.swapaxes(rotation, 1, 2) @ rotation
    if not np.allclose(gram, np.eye(3), atol=1e-4) or np.any(np.linalg.det(rotation) < 0.0):
        return None
    return rotation, matrices[:, :3, 3].copy(), semi_axes


def repair_matrix_world(matrix, flip_axis=None, tol=ORTHONORMAL_TOL):
    """A valid ellipsoid frame for an object matrix that is not one (negative scale or shear).

    Any invertible affine map L sends the unit sphere to an ellipsoid, the one with shape matrix
    L L^T, so the repair is exact: the returned (rotation, center, semi_axes) describe the same
    point set. A left-handed but orthogonal frame gets one axis flipped (``flip_axis``, else the
    axis most aligned with world X); a sheared one gets the principal axes of L L^T, labelled to
    agree with L's own axes. A valid matrix comes back unchanged. Raises FrameError for a
    zero-volume (singular) matrix, which no ellipsoid matches.
    """
    matrix = np.asarray(matrix, dtype=float)
    if matrix.shape != (4, 4) or not np.all(np.isfinite(matrix)):
        raise FrameError("matrix", "must be a finite 4x4 matrix")
    linear, center = matrix[:3, :3], matrix[:3, 3].copy()
    semi_axes = np.linalg.norm(linear, axis=0)
    singular = np.linalg.svd(linear, compute_uv=False)
    if singular[-1] <= 1e-9 * max(singular[0], 1e-300):
        raise FrameError(
            "scale", f"is zero along some axis (singular values {singular.tolist()}): no ellipsoid matches it", "zero"
        )
    rotation = linear / semi_axes
    if np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-4):
        if np.linalg.det(rotation) < 0.0:
            axis = mirror_axis(rotation) if flip_axis is None else flip_axis
            rotation[:, axis] = -rotation[:, axis]
        return project_to_rotation(rotation), center, semi_axes
    u, singular, _ = np.linalg.svd(linear)
    if np.linalg.det(u) < 0.0:
        u[:, 2] = -u[:, 2]
    rotation, semi_axes, _ = relabel_to_reference(u, singular, project_to_rotation(rotation))
    return rotation, center, semi_axes


@dataclass(frozen=True)
class Ellipsoid:
    """One ellipsoid: a convenience wrapper over the array functions above."""

    center: np.ndarray
    rotation: np.ndarray
    semi_axes: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "center", np.asarray(self.center, dtype=float).reshape(3))
        object.__setattr__(self, "rotation", np.asarray(self.rotation, dtype=float).reshape(3, 3))
        object.__setattr__(self, "semi_axes", np.asarray(self.semi_axes, dtype=float).reshape(3))

    @classmethod
    def sphere(cls, center, radius):
        return cls(center, np.eye(3), np.full(3, float(radius)))

    @property
    def shape(self):
        return shape_matrix(self.rotation, self.semi_axes)

    @property
    def volume(self):
        return float(volume(self.semi_axes))

    @property
    def matrix_world(self):
        return matrix_world(self.rotation, self.center, self.semi_axes)

    def support(self, direction):
        return support(self.rotation, self.center, self.semi_axes, direction)

    def support_point(self, direction):
        return support_point(self.rotation, self.center, self.semi_axes, direction)

    def section(self, height):
        return section_at_height(self.rotation, self.center, self.semi_axes, height)

    def contains(self, points, tol=0.0):
        return contains(self.rotation, self.center, self.semi_axes, points, tol)

    def sample(self, count=256):
        return sample_surface(self.rotation, self.center, self.semi_axes, count)
