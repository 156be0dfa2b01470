"""The skin measured by m_T's definitions: He from the lowest to the highest point of the surface, Sh across the
section at its height, Br, Wa and Hi the perimeter of the convex hull of the section at theirs, without the parts
m_T leaves out (the arms, whose pieces take no part in girths). The skin's own He sets the section heights.

Two ways, which agree to a fraction of a millimetre: on the surface itself (:func:`field_measurements`, the field
sampled finely in the section planes and around the top and the bottom, no mesh: what exact mode's loop over the
skin uses), and on a skin's mesh (:func:`mesh_measurements`). A vertex or a field sample belongs to the piece
nearest to it; it counts in a girth when that piece does.
"""

import numpy as np

from ..constants import CM_PER_M, GIRTHS, SECTION_FRACTIONS
from ..geometry.ellipsoid import bounds
from ..geometry.mesh import convex_hull_2d, polygon_perimeter, section_segments
from ..measure.body import measure_body_mesh
from ..measure.extra import SIDES, MannequinLandmarks, mannequin_tilt
from ..measurements import MEASUREMENTS
from .field import FADE, Grid, skin_pieces

SECTION_COARSE = 0.004  # m between the samples of a section plane whose grid edges bracket the surface
ROOT_STEPS = 8  # regula-falsi steps along each bracketing edge
EXTREME_COARSE = 0.004  # m between the samples that find where the top (bottom) is
EXTREME_FINE = np.array([0.0005, 0.0005, 0.0001])  # m between those that find its height
MARGIN = 0.01  # m around what the pieces reach at a height


def mesh_measurements(skin, fractions=None):
    """{He, Sh, Br, Wa, Hi: cm} of a skin's mesh (a ``core.skin.surface.Skin``)."""
    fractions = fractions or skin.mannequin.section_fractions or SECTION_FRACTIONS
    vertices, faces = skin.vertices, skin.faces
    bottom, top = vertices[:, 2].min(), vertices[:, 2].max()
    height = top - bottom
    girth_vertex = skin.mannequin.topology.girth_mask[skin.pieces[:, 0]]
    out = {"He": height}
    for key in ("Sh",) + GIRTHS:
        z = bottom + fractions[key] * height
        segments, rows = section_segments(vertices, faces, z)
        if key == "Sh":
            out[key] = float(np.ptp(segments[:, :, 0])) if len(segments) else 0.0
            continue
        kept = segments[girth_vertex[faces[rows]].any(axis=1)].reshape(-1, 2)
        out[key] = polygon_perimeter(convex_hull_2d(kept)) if len(kept) >= 3 else 0.0
    return {key: float(out[key]) * CM_PER_M for key in MEASUREMENTS}


def skin_arms(skin):
    """{"L", "R": (V,) bool}: the skin's vertices that follow an arm's or a hand's piece first (the pieces the
    extra measurements take as the arms)."""
    marks = MannequinLandmarks(skin.mannequin)
    first = skin.pieces[:, 0]
    return {side: (marks.arm & (marks.side == side))[first] for side in SIDES}


def body_measurements(skin, fractions=None):
    """The skin's mesh measured by the body-mesh measurer (core.measure.body: the extra measurements' definitions
    on any mesh) with its arms known (:func:`skin_arms`), not searched for by geometry: an arm that touches the
    torso is still an arm; the neck square to the mannequin's own neck axis (``mannequin_tilt``, as its pieces'
    neck is taken), not to a tilt searched on the mesh, which jumps between nearby skins. A BodyMeasurement."""
    fractions = fractions or skin.mannequin.section_fractions
    tilt = mannequin_tilt(skin.mannequin)
    return measure_body_mesh(skin.vertices, skin.faces, fractions, neck_tilt=tilt, arms=skin_arms(skin))


class SkinField:
    """The skin's field of a mannequin at its settings, sampled where a measurement needs it. It keeps the gaps
    build_skin keeps; where build_skin gives them up (a skin with fewer handles without them), its mesh measures
    a little otherwise near the arms, which exact mode's last round, on the mesh, makes up."""

    def __init__(self, mannequin, settings):
        self.mannequin = mannequin
        self.pieces = skin_pieces(mannequin, settings.blend, settings.voxel)
        self.widths = self.pieces.widths
        self.lo, self.hi = bounds(mannequin.rotation, mannequin.center, mannequin.semi_axes)
        self.girth = mannequin.topology.girth_mask
        self.reach = FADE * max(self.widths, default=0.0) + MARGIN  # how far the surface can stand off a piece

    def sample(self, lo, hi, spacing, pieces=None):
        """(values, nearest piece (flat), Grid) on a grid from ``lo`` to ``hi`` (3-vectors), of ``pieces``
        (default: all)."""
        shape = tuple(int(n) for n in np.maximum(np.ceil((hi - lo) / spacing), 0) + 1)
        grid = Grid(np.asarray(lo, float), spacing, shape)
        values, nearest = (pieces or self.pieces).field(grid, np.ones(shape, dtype=bool), self.reach)
        return values, nearest, grid

    def section(self, z):
        """The crossing points (k, 2) of the surface with the plane z, on the edges of a grid SECTION_COARSE apart
        (each found by regula falsi along its edge), and whether each belongs to a piece that takes part in
        girths."""
        near = (self.lo[:, 2] - self.reach <= z) & (self.hi[:, 2] + self.reach >= z)
        lo = np.append(self.lo[near, :2].min(axis=0) - self.reach, z)
        hi = np.append(self.hi[near, :2].max(axis=0) + self.reach, z)
        pieces, kept = self.pieces.subset(np.flatnonzero(near))  # the others stay beyond reach of the plane
        values, nearest, grid = self.sample(lo, hi, SECTION_COARSE, pieces)
        nearest = kept[nearest]
        values, nearest = values[:, :, 0], nearest.reshape(grid.shape)[:, :, 0]
        inner, outer, girth = [], [], []
        for axis in (0, 1):
            count = values.shape[axis] - 1
            a, b = values.take(np.arange(count), axis=axis), values.take(np.arange(1, count + 1), axis=axis)
            crossing = np.nonzero((a < 0.0) != (b < 0.0))
            start = grid.origin[:2] + SECTION_COARSE * np.stack(crossing, axis=1)
            end = start.copy()
            end[:, axis] += SECTION_COARSE
            first_inside = a[crossing] < 0.0
            inner.append(np.where(first_inside[:, None], start, end))
            outer.append(np.where(first_inside[:, None], end, start))
            owner = np.where(first_inside, nearest.take(np.arange(count), axis=axis)[crossing], 0)
            owner = np.where(first_inside, owner, nearest.take(np.arange(1, count + 1), axis=axis)[crossing])
            girth.append(self.girth[owner])
        return self._root(pieces, np.concatenate(inner), np.concatenate(outer), z), np.concatenate(girth)

    def _root(self, pieces, inner, outer, z):
        """The surface's crossing on each segment from an inside point to an outside one (k, 2) at height z:
        regula falsi (Illinois) to a micrometre."""

        def at(points):
            return pieces.at(np.c_[points, np.full(len(points), z)], self.reach)[0]

        f_in, f_out = at(inner), at(outer)
        for _ in range(ROOT_STEPS):
            point = inner + (f_in / (f_in - f_out))[:, None] * (outer - inner)
            value = at(point)
            inside = value < 0.0
            # Illinois: halve the value kept at the end that stays, so that the bracket shrinks from both sides
            f_out = np.where(inside, f_out * 0.5, value)
            f_in = np.where(inside, value, f_in * 0.5)
            inner = np.where(inside[:, None], point, inner)
            outer = np.where(inside[:, None], outer, point)
        return inner + (f_in / (f_in - f_out))[:, None] * (outer - inner)

    def extreme(self, highest):
        """The height of the surface's top (``highest``) or bottom: coarse samples over the pieces that reach
        nearest to it find where, fine ones around that spot how high (the crossing of the field along
        vertical lines)."""
        sign = 1.0 if highest else -1.0
        reach = sign * (self.hi[:, 2] if highest else self.lo[:, 2])
        near = reach >= reach.max() - self.reach
        limit = sign * reach.max()  # the pieces' own top (bottom): the surface is there or beyond
        beyond = sign * (0.5 * max(self.widths, default=0.0) + EXTREME_COARSE)
        lo = np.append(self.lo[near, :2].min(axis=0) - self.reach, min(limit - sign * EXTREME_COARSE, limit + beyond))
        hi = np.append(self.hi[near, :2].max(axis=0) + self.reach, max(limit - sign * EXTREME_COARSE, limit + beyond))
        spot = self._crossing(lo, hi, np.full(3, EXTREME_COARSE), highest)
        around = np.array([EXTREME_COARSE * 1.5, EXTREME_COARSE * 1.5, EXTREME_COARSE * 1.5])
        return float(self._crossing(spot - around, spot + around, EXTREME_FINE, highest)[2])

    def _crossing(self, lo, hi, spacing, highest):
        """The highest (lowest) point of the surface sampled on a grid lo..hi: (x, y, z)."""
        shape = tuple(int(n) for n in np.ceil((hi - lo) / spacing) + 1)
        grid = Grid(np.asarray(lo, float), np.asarray(spacing, float), shape)
        values = self.pieces.field(grid, np.ones(shape, dtype=bool), self.reach)[0]
        inside = values < 0.0
        last = shape[2] - 1
        k = last - np.argmax(inside[..., ::-1], axis=2) if highest else np.argmax(inside, axis=2)
        beside = np.clip(k + (1 if highest else -1), 0, last)
        f0 = np.take_along_axis(values, k[..., None], axis=2)[..., 0]
        f1 = np.take_along_axis(values, beside[..., None], axis=2)[..., 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(beside != k, f0 / (f0 - f1), 0.0) * (1 if highest else -1)
        z = np.where(inside.any(axis=2), grid.origin[2] + grid.spacing[2] * (k + step), -np.inf if highest else np.inf)
        column = np.unravel_index(np.argmax(z) if highest else np.argmin(z), z.shape)
        return np.array([*(grid.origin[:2] + grid.spacing[:2] * np.array(column)), z[column]])


def field_measurements(mannequin, settings, fractions=None):
    """{He, Sh, Br, Wa, Hi: cm} of the skin of ``mannequin`` at ``settings``, on the surface itself."""
    fractions = fractions or mannequin.section_fractions or SECTION_FRACTIONS
    field = SkinField(mannequin, settings)
    bottom, top = field.extreme(False), field.extreme(True)
    out = {"He": top - bottom}
    for key in ("Sh",) + GIRTHS:
        points, girth = field.section(bottom + fractions[key] * (top - bottom))
        if key == "Sh":
            out[key] = float(np.ptp(points[:, 0])) if len(points) else 0.0
        else:
            kept = points[girth]
            out[key] = polygon_perimeter(convex_hull_2d(kept)) if len(kept) >= 3 else 0.0
    return {key: float(out[key]) * CM_PER_M for key in MEASUREMENTS}
