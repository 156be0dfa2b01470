"""m_T, the tailor measuring of Section 2.3.5, in closed form and batched.

- He: top of the highest ellipsoid minus bottom of the lowest (support function along +-Z).
- Br, Wa, Hi: the horizontal section at fractions[key] * He above the lowest point (the section heights of
  the mannequin's reference set; SECTION_FRACTIONS, the female ones, by default),
  through the ellipsoids flagged ``girth``; each ellipsoid's section is an ellipse in closed form
  (:func:`ellipsoid.section_at_height`); the perimeter of the convex hull of those ellipses is
  Cauchy's formula  P = integral_0^2pi max_i h_i(theta) dtheta  with h_i their support functions.
- Sh: the section at the shoulder height through all ellipsoids; distance between the two
  outermost points along X (the paper's Y), again from support functions.

The integral is evaluated exactly up to floating point (``core.geometry.section_hull``: kinks of max_i h_i from a grid
scan with a rigorous bound and Newton steps, each smooth piece by closed form and Gauss-Legendre quadrature).
"""

import numpy as np

from ..constants import CM_PER_M, GIRTHS, SECTION_FRACTIONS
from ..geometry.ellipse_support import hull_boundary
from ..geometry.ellipsoid import axis_extent, section_at_height, section_shape
from ..geometry.mesh import convex_hull_2d, plane_section_points, polygon_perimeter
from ..geometry.section_hull import HullStructure, hull_perimeter
from ..measurements import MEASUREMENTS

_CHUNK = 256  # mannequins per batch chunk (bounds the temporary arrays to tens of MB)


def section_heights(rotation, center, semi_axes, fractions=None):
    """Lowest point, He (m) and the world z of each section, for arrays (..., n, 3[, 3]).

    ``fractions``: the section heights {Sh, Br, Wa, Hi} as fractions of He (default SECTION_FRACTIONS)."""
    z_half = axis_extent(rotation, semi_axes, 2)
    top = np.max(center[..., 2] + z_half, axis=-1)
    bottom = np.min(center[..., 2] - z_half, axis=-1)
    height = top - bottom
    fractions = fractions or SECTION_FRACTIONS
    z = {key: bottom + fractions[key] * height for key in SECTION_FRACTIONS}
    return bottom, height, z


def tailor_measurements(rotation, center, semi_axes, girth, fractions=None):
    """m_T for one mannequin (n, ...) or a batch (B, n, ...): array (..., 5) in cm, order MEASUREMENTS.

    ``girth`` (n,) bool marks the ellipsoids that take part in the Br/Wa/Hi sections; ``fractions`` the
    section heights (default SECTION_FRACTIONS, the female set's).
    """
    rotation = np.asarray(rotation, dtype=float)
    center = np.asarray(center, dtype=float)
    semi_axes = np.asarray(semi_axes, dtype=float)
    girth = np.asarray(girth, dtype=bool)
    single = rotation.ndim == 3
    if single:
        rotation, center, semi_axes = rotation[None], center[None], semi_axes[None]
    out = (
        np.concatenate(
            [
                _measure_chunk(
                    rotation[i : i + _CHUNK], center[i : i + _CHUNK], semi_axes[i : i + _CHUNK], girth, fractions
                )[0]
                for i in range(0, rotation.shape[0], _CHUNK)
            ]
        )
        if rotation.shape[0]
        else np.zeros((0, len(MEASUREMENTS)))
    )
    return out[0] if single else out


def followed_measurements(rotation, center, semi_axes, girth, fractions=None, warm=None):
    """m_T of a batch (B, n, ...) as :func:`tailor_measurements`, and where the outermost piece of each girth section
    changes (a :class:`core.geometry.section_hull.HullStructure` of B * 3 sections, mannequin by mannequin in GIRTHS
    order, pieces by part index), for measuring the same mannequins again after a small change. With ``warm`` (such a
    structure) the girths follow it instead of searching (``hull_perimeter``'s warm): for a refinement's steps, not a
    result.
    """
    rotation, center, semi_axes = (np.asarray(a, dtype=float) for a in (rotation, center, semi_axes))
    girth = np.asarray(girth, dtype=bool)
    values, structures = [], []
    for i in range(0, rotation.shape[0], _CHUNK):
        chunk = slice(i, i + _CHUNK)
        rows = np.arange(len(GIRTHS) * i, len(GIRTHS) * min(i + _CHUNK, rotation.shape[0]))
        value, structure = _measure_chunk(
            rotation[chunk],
            center[chunk],
            semi_axes[chunk],
            girth,
            fractions,
            None if warm is None else warm.take(rows),
            follow=True,
        )
        values.append(value)
        structures.append(structure)
    if not values:
        return np.zeros((0, len(MEASUREMENTS))), HullStructure.concatenate([])
    return np.concatenate(values), HullStructure.concatenate(structures)


def _measure_chunk(rotation, center, semi_axes, girth, fractions, warm=None, follow=False):
    batch = rotation.shape[0]
    _, height, z = section_heights(rotation, center, semi_axes, fractions)
    result = {"He": height}
    # Each section only through the parts that reach its height in some mannequin of the chunk (with a margin:
    # whether a part is cut is decided below, as for every part; those left out would not be cut, and a part's
    # section does not depend on which others are computed with it).
    reach = axis_extent(rotation, semi_axes, 2) * (1.0 + 1e-9)

    def cut(key, parts):
        return parts[np.any(np.abs(z[key][:, None] - center[:, parts, 2]) <= reach[:, parts], axis=0)]

    parts = cut("Sh", np.arange(rotation.shape[1]))
    shape = section_shape(rotation[:, parts], semi_axes[:, parts])
    centre, k, hit = section_at_height(
        rotation[:, parts], center[:, parts], semi_axes[:, parts], z["Sh"][:, None], shape
    )
    half_x = np.sqrt(k[..., 0, 0])
    right = np.where(hit, centre[..., 0] + half_x, -np.inf).max(axis=-1, initial=-np.inf)
    left = np.where(hit, centre[..., 0] - half_x, np.inf).min(axis=-1, initial=np.inf)
    result["Sh"] = np.where(np.isfinite(right), right - left, 0.0)

    # The girth sections through the girth parts only (the others would only be dropped).
    girth_parts = np.nonzero(girth)[0]
    parts = np.unique(np.concatenate([cut(key, girth_parts) for key in GIRTHS]))
    heights = np.stack([z[key] for key in GIRTHS], axis=1)  # (B, 3)
    rotation, center, semi_axes = rotation[:, None, parts], center[:, None, parts], semi_axes[:, None, parts]
    centre, k, hit = section_at_height(
        rotation, center, semi_axes, heights[:, :, None], section_shape(rotation, semi_axes)
    )
    sections, n = batch * len(GIRTHS), len(parts)
    if warm is not None:  # the structure names pieces by part index; hull_perimeter by column
        column = np.full(len(girth), -1)
        column[parts] = np.arange(n)
        warm = warm.renamed(column)
    found = hull_perimeter(
        centre.reshape(sections, n, 2),
        k.reshape(sections, n, 2, 2),
        hit.reshape(sections, n),
        warm=warm,
        structure=follow,
    )
    perimeters, structure = found if follow else (found, None)
    for index, key in enumerate(GIRTHS):
        result[key] = perimeters.reshape(batch, len(GIRTHS))[:, index]
    values = np.stack([result[key] for key in MEASUREMENTS], axis=-1) * CM_PER_M
    return values, structure.renamed(parts) if follow else None


def as_dict(values):
    """(5,) array in MEASUREMENTS order -> {"He": ..., ...} of plain floats."""
    return {key: float(value) for key, value in zip(MEASUREMENTS, values)}


def section_hulls(rotation, center, semi_axes, girth, samples=256, fractions=None):
    """The sections m_T measures, for drawing: {key: (z, hull points (k, 2))} for Sh, Br, Wa, Hi.

    Sh's section runs through every ellipsoid, the girths' only through those flagged ``girth``;
    the points follow the convex hull of the section ellipses (:func:`hull_boundary`).
    """
    rotation = np.asarray(rotation, dtype=float)
    center = np.asarray(center, dtype=float)
    semi_axes = np.asarray(semi_axes, dtype=float)
    girth = np.asarray(girth, dtype=bool)
    _, _, z = section_heights(rotation, center, semi_axes, fractions)
    out = {}
    for key in z:
        centre, k, hit = section_at_height(rotation, center, semi_axes, z[key])
        active = hit if key == "Sh" else hit & girth
        out[key] = (float(z[key]), hull_boundary(centre, k, active, samples))
    return out


def _concatenate(meshes):
    vertices = [np.asarray(v, dtype=float).reshape(-1, 3) for v, _ in meshes]
    offsets = np.cumsum([0] + [len(v) for v in vertices[:-1]])
    faces = [np.asarray(f, dtype=np.int64).reshape(-1, 3) + o for (_, f), o in zip(meshes, offsets)]
    if not vertices:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    return np.concatenate(vertices), np.concatenate(faces)


def measure_meshes(meshes, girth, fractions=None):
    """m_T of a body made of closed triangle meshes in world space (e.g. a cushion mannequin).

    ``meshes`` is a sequence of (vertices (V, 3), faces (F, 3)); ``girth`` one bool per mesh.
    He is the z extent of all vertices; the section heights are the same fractions of He as for
    ellipsoids. Br, Wa, Hi: perimeter of the 2D convex hull of the points where the girth meshes'
    edges cross the section plane. Sh: x extent of the section of all meshes at the shoulder height.
    ``fractions``: the section heights (default SECTION_FRACTIONS).
    Returns (values (5,) in cm in MEASUREMENTS order, {key: (z, hull polygon (h, 2))}).
    """
    girth = np.asarray(girth, dtype=bool)
    if len(meshes) == 0 or len(girth) != len(meshes):
        raise ValueError(
            f"need one girth flag per mesh and at least one mesh; got {len(meshes)} meshes and {len(girth)} flags"
        )
    everything = _concatenate(meshes)
    girth_only = _concatenate([m for m, g in zip(meshes, girth) if g])
    bottom, top = everything[0][:, 2].min(), everything[0][:, 2].max()
    height = top - bottom
    values = {"He": height}
    sections = {}
    fractions = fractions or SECTION_FRACTIONS
    for key in SECTION_FRACTIONS:
        z = bottom + fractions[key] * height
        points = plane_section_points(*(everything if key == "Sh" else girth_only), z)
        hull = convex_hull_2d(points) if len(points) else np.zeros((0, 2))
        sections[key] = (float(z), hull)
        if key == "Sh":
            values[key] = float(np.ptp(points[:, 0])) if len(points) else 0.0
        else:
            values[key] = polygon_perimeter(hull) if len(hull) >= 3 else 0.0
    return np.array([values[key] for key in MEASUREMENTS]) * CM_PER_M, sections
