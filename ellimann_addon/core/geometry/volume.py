"""Volumes of a closed body mesh and of a mannequin's pieces on a regular grid: which cells are inside
the body (vertical rays), which inside a piece (closed form per convex piece), and from them how much
of its body a mannequin fills (coverage) and how much of it lies outside (excess).

Pieces are the ellipsoids or, with ``cushions``, the hulls of the cushion pairs (and the single
ellipsoids). A point is inside the closed body mesh when a vertical line through it crosses the surface
an odd number of times above it; a piece, being convex, meets each vertical line in one interval
(closed form for an ellipsoid, from the face planes of a hull mesh of 642 support points per ellipsoid,
a little inside the true hull, for a cushion).
"""

from dataclasses import dataclass

import numpy as np

from .cushion import cushion_mesh, cushion_name
from .ellipsoid import bounds

GRID_SPACING = 0.005  # m: 5 mm resolves fingers and toes; a body is ~0.5 million points
_OFFSET = (0.3719, 0.6143, 0.2281)  # grid origin in cells past the body's corner: no ray on a mesh edge
_BUCKET = 0.01  # m: cell of the triangle index used by the vertical rays
_CUSHION_SUBDIVISIONS = 3  # hull meshes for the metrics (642 support points per ellipsoid)
_NUDGE = (1.3e-7, 0.7e-7)  # m: moves a query line off the mesh edges that lie in the sagittal plane


class BodyVolume:
    """A closed, outward-wound triangle mesh: which points are inside it, by vertical rays."""

    def __init__(self, vertices, faces):
        self.vertices = np.asarray(vertices, dtype=float)
        self.faces = np.asarray(faces)
        tri = self.vertices[self.faces]
        self._tri = tri
        lo = tri[..., :2].min(axis=1)
        hi = tri[..., :2].max(axis=1)
        self._corner = self.vertices[:, :2].min(axis=0) - _BUCKET
        first = np.floor((lo - self._corner) / _BUCKET).astype(int)
        last = np.floor((hi - self._corner) / _BUCKET).astype(int)
        self._width = int(last[:, 1].max()) + 2
        span = last - first + 1
        count = span[:, 0] * span[:, 1]
        owner = np.repeat(np.arange(len(tri)), count)
        k = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
        cell = (first[owner, 0] + k // span[owner, 1]) * self._width + first[owner, 1] + k % span[owner, 1]
        order = np.argsort(cell, kind="stable")
        self._cell, self._cell_tri = cell[order], owner[order]

    def crossings(self, xy):
        """Where vertical lines at ``xy`` (C, 2) cross the surface: (line index (K,), z (K,))."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2) + _NUDGE
        ij = np.floor((xy - self._corner) / _BUCKET).astype(int)
        known = np.all(ij >= 0, axis=1) & (ij[:, 1] < self._width)
        cell = np.where(known, ij[:, 0] * self._width + ij[:, 1], -1)  # -1: no triangle there
        lo = np.searchsorted(self._cell, cell, side="left")
        hi = np.searchsorted(self._cell, cell, side="right")
        count = hi - lo
        line = np.repeat(np.arange(len(xy)), count)
        tri = self._cell_tri[np.repeat(lo, count) + np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)]
        a, b, c = (self._tri[tri, i] for i in range(3))
        p = xy[line]
        # barycentric coordinates of the line's foot in the triangle's projection
        det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            u = ((p[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (p[:, 1] - a[:, 1])) / det
            v = ((b[:, 0] - a[:, 0]) * (p[:, 1] - a[:, 1]) - (p[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])) / det
            hit = (det != 0.0) & (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0)
        z = a[hit, 2] + u[hit] * (b[hit, 2] - a[hit, 2]) + v[hit] * (c[hit, 2] - a[hit, 2])
        return line[hit], z

    def contains(self, points):
        """True for points inside the surface (odd number of crossings above)."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        line, z = self.crossings(points[:, :2])
        above = np.bincount(line, weights=z > points[line, 2], minlength=len(points))
        return above.astype(int) % 2 == 1

    def grid(self, spacing=GRID_SPACING, margin=0.05):
        """A regular grid around the body with its inside mask (see :class:`Grid`)."""
        lo = self.vertices.min(axis=0) - margin + np.asarray(_OFFSET) * spacing
        shape = np.ceil((self.vertices.max(axis=0) + margin - lo) / spacing).astype(int)
        return Grid(lo, spacing, self.cells_inside(lo, spacing, shape))

    def cells_inside(self, origin, spacing, shape):
        """(nx, ny, nz) bool: which cells of a grid (cell (0, 0, 0) centred at ``origin``, ``spacing`` apart) have
        their centre inside the surface. ValueError if a vertical ray crosses it an odd number of times."""
        xs, ys = (origin[k] + spacing * np.arange(shape[k]) for k in (0, 1))
        xy = np.stack(np.meshgrid(xs, ys, indexing="ij"), axis=-1).reshape(-1, 2)
        line, z = self.crossings(xy)
        # a cell is inside when an odd number of crossings lies below it
        first_above = np.clip(np.ceil((z - origin[2]) / spacing).astype(int), 0, shape[2])
        steps = np.zeros((len(xy), shape[2] + 1), dtype=np.int32)
        np.add.at(steps, (line, first_above), 1)
        odd_columns = int(np.count_nonzero(steps.sum(axis=1) % 2))
        if odd_columns:
            raise ValueError(f"{odd_columns} vertical rays cross the body an odd number of times: not a closed mesh")
        return (np.cumsum(steps[:, :-1], axis=1) % 2 == 1).reshape(tuple(shape))


@dataclass
class Grid:
    origin: np.ndarray  # (3,) m, centre of cell (0, 0, 0)
    spacing: float
    inside: np.ndarray  # (nx, ny, nz) bool: the cell's centre is inside the body

    def box(self, lo, hi):
        """Index ranges (slices) and centres of the cells whose centres lie in the box [lo, hi]."""
        first = np.maximum(np.ceil((np.asarray(lo) - self.origin) / self.spacing).astype(int), 0)
        last = np.minimum(
            np.floor((np.asarray(hi) - self.origin) / self.spacing).astype(int), np.array(self.inside.shape) - 1
        )
        if np.any(last < first):
            return None, None
        slices = tuple(slice(f, t + 1) for f, t in zip(first, last))
        axes = [self.origin[k] + self.spacing * np.arange(first[k], last[k] + 1) for k in range(3)]
        centres = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
        return slices, centres


def pieces(mannequin, cushions=False):
    """The mannequin's solid pieces: [(name, part indices)] (one per ellipsoid, or per cushion)."""
    topology = mannequin.topology
    out, done = [], set()
    for i, part in enumerate(topology):
        if i in done:
            continue
        if cushions and part.partner:
            j = topology.index[part.partner]
            done.add(j)
            out.append((cushion_name(part.name, part.partner), (i, j)))
        else:
            out.append((part.name, (i,)))
    return out


def _ellipsoid(mannequin, i):
    return mannequin.rotation[i], mannequin.center[i], mannequin.semi_axes[i]


def _hull(mannequin, indices, subdivisions=_CUSHION_SUBDIVISIONS):
    """Hull mesh (vertices, faces) of a piece: a cushion, or one ellipsoid."""
    return cushion_mesh(_ellipsoid(mannequin, indices[0]), _ellipsoid(mannequin, indices[-1]), subdivisions)


def _ellipsoid_spans(rotation, center, semi_axes, xy):
    """(low, high) z where vertical lines at ``xy`` (C, 2) are inside an ellipsoid (low > high: missed)."""
    q = (rotation / semi_axes**2) @ rotation.T  # inverse shape matrix
    d = xy - center[:2]
    b = d @ q[:2, 2]
    c = np.einsum("ci,ij,cj->c", d, q[:2, :2], d) - 1.0
    disc = b * b - q[2, 2] * c
    root = np.sqrt(np.maximum(disc, 0.0))
    low = center[2] + (-b - root) / q[2, 2]
    high = center[2] + (-b + root) / q[2, 2]
    return np.where(disc >= 0.0, low, np.inf), np.where(disc >= 0.0, high, -np.inf)


def _polytope_spans(vertices, faces, xy):
    """(low, high) z where vertical lines at ``xy`` (C, 2) are inside a closed convex, outward-wound mesh."""
    tri = vertices[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    offset = np.einsum("ij,ij->i", normal, tri[:, 0])
    rest = offset[None, :] - xy @ normal[:, :2].T  # (C, F): normal_z z <= rest
    nz = normal[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = rest / nz
    high = np.where(nz > 0.0, bound, np.inf).min(axis=1)
    low = np.where(nz < 0.0, bound, -np.inf).max(axis=1)
    blocked = np.any((nz == 0.0) & (rest < 0.0), axis=1)
    return np.where(blocked, np.inf, low), np.where(blocked, -np.inf, high)


def occupancy(grid, mannequin, cushions=False, hulls=None):
    """Bool mask over the grid's cells: inside any piece of the mannequin (each piece is convex, so a
    vertical line meets it in one interval, computed in closed form for an ellipsoid and from the
    face planes of a cushion's hull). ``hulls``: {piece indices: hull mesh}, to reuse."""
    shape = grid.inside.shape
    steps = np.zeros((shape[0], shape[1], shape[2] + 1), dtype=np.int32)
    for _, indices in pieces(mannequin, cushions):
        at = list(indices)
        lo, hi = bounds(mannequin.rotation[at], mannequin.center[at], mannequin.semi_axes[at])
        slices, centres = grid.box(lo.min(axis=0), hi.max(axis=0))
        if slices is None:
            continue
        xy = centres[:, :, 0, :2].reshape(-1, 2)
        if len(indices) == 1:
            low, high = _ellipsoid_spans(*_ellipsoid(mannequin, indices[0]), xy)
        else:
            hull = hulls[indices] if hulls is not None else _hull(mannequin, indices)
            low, high = _polytope_spans(*hull, xy)
        first = np.ceil((low - grid.origin[2]) / grid.spacing)
        last = np.floor((high - grid.origin[2]) / grid.spacing)
        hit = (first <= last) & np.isfinite(first) & np.isfinite(last)
        first = np.clip(first[hit], 0, shape[2]).astype(int)
        last = np.clip(last[hit] + 1, 0, shape[2]).astype(int)
        ix, iy = np.unravel_index(np.nonzero(hit)[0], centres.shape[:2])
        ix, iy = ix + slices[0].start, iy + slices[1].start
        np.add.at(steps, (ix, iy, first), 1)
        np.add.at(steps, (ix, iy, last), -1)
    return np.cumsum(steps[..., :-1], axis=2) > 0


def fill_shares(grid, mannequin, hulls=None, hollow=None):
    """{"ellipsoids" | "cushions": {"coverage", "excess"}}: the share of the body's volume (``grid``'s
    inside cells) inside the union of the pieces, and the share of the pieces' volume outside the body.
    ``hulls``: {piece indices: hull mesh}, to reuse (see :func:`cushion_hulls`); ``hollow``: cells outside the mesh
    that a solid body fills (a mesh's open mouth and eye sockets), bool over the grid: no excess, no coverage due."""
    hulls = cushion_hulls(mannequin) if hulls is None else hulls
    solid = grid.inside if hollow is None else grid.inside | hollow
    out = {}
    for key, cushions in (("ellipsoids", False), ("cushions", True)):
        occupied = occupancy(grid, mannequin, cushions, hulls)
        covered = np.count_nonzero(occupied & grid.inside)
        out[key] = {
            "coverage": covered / np.count_nonzero(grid.inside),
            "excess": 1.0 - np.count_nonzero(occupied & solid) / max(np.count_nonzero(occupied), 1),
        }
    return out


def cushion_hulls(mannequin):
    """{(i, j): hull mesh} of every cushion pair."""
    return {indices: _hull(mannequin, indices) for _, indices in pieces(mannequin, True) if len(indices) == 2}


IOU_SPACING = 0.005  # m: the voxels of voxel_iou
IOU_MARGIN = 0.15  # m: voxels around the body, so a mannequin reaching out of it is counted whole


def voxel_iou(mannequin, vertices=None, faces=None, cushions=True, spacing=IOU_SPACING, grid=None):
    """Volumetric IoU (intersection over union, voxelized) of a mannequin's pieces (``cushions``: the cushion
    hulls and single ellipsoids; else the ellipsoids) and a closed body mesh (``vertices``, ``faces``, in the
    mannequin's frame). ``grid``: the body's grid (``BodyVolume(...).grid(spacing, margin=IOU_MARGIN)``) to
    reuse instead of the mesh. 1 when they fill the same voxels, 0 when they share none."""
    if grid is None:
        grid = BodyVolume(vertices, faces).grid(spacing, margin=IOU_MARGIN)
    occupied = occupancy(grid, mannequin, cushions, cushion_hulls(mannequin) if cushions else None)
    return np.count_nonzero(occupied & grid.inside) / max(np.count_nonzero(occupied | grid.inside), 1)


def mesh_voxel_iou(vertices, faces, grid):
    """Volumetric IoU, as :func:`voxel_iou`, of a closed, outward-wound triangle mesh (a skin, in the body's frame)
    and the body of ``grid`` (``BodyVolume(...).grid(spacing, margin=IOU_MARGIN)``), on the grid's voxels; the
    mesh's voxels beyond the grid are not counted (the margin holds anything near the body)."""
    occupied = BodyVolume(vertices, faces).cells_inside(grid.origin, grid.spacing, grid.inside.shape)
    return np.count_nonzero(occupied & grid.inside) / max(np.count_nonzero(occupied | grid.inside), 1)
