"""Fitting an ellipsoid to points (e.g. the selected vertices of a reference mesh)."""

import numpy as np

from ..geometry.frames import relabel_to_reference

FIT_MODES = ("inscribed", "moments", "enclosing")


def fit_ellipsoid(points, mode="inscribed", surface=None):
    """Principal-axes ellipsoid of surface points: (rotation, center, semi_axes), right-handed.

    The axes are the principal directions of the points, labelled to agree best with the world
    axes. Sizes: ``moments`` matches the second moments of points spread over an ellipsoid's
    surface (D_i = sqrt(3 lambda_i)); ``inscribed`` scales that shape down until no point lies
    inside it, nor any of ``surface`` (m, 3), the rest of the traced surface, if given: an
    ellipsoid inside a closed surface contains none of its vertices, while one fitted to part of
    it (a patch on one side of a body) would otherwise reach through the unselected rest;
    ``enclosing`` scales it up until every point is inside.
    """
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) < 4:
        raise ValueError("need at least 4 points (n, 3) to fit an ellipsoid")
    if not np.all(np.isfinite(points)):
        raise ValueError("points contain NaN or infinity")
    if mode not in FIT_MODES:
        raise ValueError(f"mode is '{mode}'; expected one of {', '.join(FIT_MODES)}")
    surface = np.zeros((0, 3)) if surface is None else np.asarray(surface, dtype=float).reshape(-1, 3)
    if not np.all(np.isfinite(surface)):
        raise ValueError("surface points contain NaN or infinity")
    center = points.mean(axis=0)
    offsets = points - center
    eigenvalues, rotation = np.linalg.eigh(offsets.T @ offsets / len(points))
    if eigenvalues[0] <= 1e-14 * max(eigenvalues[-1], 1e-300):
        raise ValueError("points are (nearly) coplanar: select vertices that enclose a volume")
    if np.linalg.det(rotation) < 0.0:
        rotation[:, 0] = -rotation[:, 0]
    semi_axes = np.sqrt(3.0 * eigenvalues)
    rotation, semi_axes, _ = relabel_to_reference(rotation, semi_axes, np.eye(3))
    if mode == "inscribed":
        radius = np.linalg.norm(np.concatenate([offsets, surface - center]) @ rotation / semi_axes, axis=1)
        semi_axes = semi_axes * radius.min()
    elif mode == "enclosing":
        semi_axes = semi_axes * np.linalg.norm(offsets @ rotation / semi_axes, axis=1).max()
    return rotation, center, semi_axes


def fit_affine(source, target):
    """Least-squares affine map with target ~ source @ A.T + t for corresponding points.

    Returns (4x4 matrix [[A, t], [0, 1]], largest residual distance). Used to recover the
    transform that was applied to a known mesh (e.g. a unit sphere whose scale was applied).
    """
    source = np.asarray(source, dtype=float)
    target = np.asarray(target, dtype=float)
    if source.shape != target.shape or source.ndim != 2 or source.shape[1] != 3 or len(source) < 4:
        raise ValueError(
            f"need two (n, 3) arrays of corresponding points, n >= 4; got shapes {source.shape} and {target.shape}"
        )
    design = np.column_stack([source, np.ones(len(source))])
    solution, *_ = np.linalg.lstsq(design, target, rcond=None)
    matrix = np.eye(4)
    matrix[:3, :3] = solution[:3].T
    matrix[:3, 3] = solution[3]
    residual = float(np.linalg.norm(design @ solution - target, axis=1).max())
    return matrix, residual
