"""How well a mannequin fills the body it was traced from: coverage, excess and gaps along the limbs.

- **coverage**: share of the body's volume inside the union of the mannequin's pieces;
- **excess**: share of the pieces' volume outside the body; **depth**: how far (m) a piece reaches
  outside the body surface at most (leaving out the mesh's open mouth and eye sockets, if given);
- **gaps**: along each chain of CHAINS (e.g. thigh, knee, calf, ankle, foot, toes), the distance
  between each two consecutive links (0 where they touch or overlap).

Pieces are the ellipsoids or, with ``cushions``, the hulls of the cushion pairs (and the single
ellipsoids). Volumes are counted on a regular grid: a point is inside the closed body mesh when a
vertical line through it crosses the surface an odd number of times above it; a piece, being convex,
meets each vertical line in one interval (closed form for an ellipsoid, from the face planes of a
hull mesh of 642 support points per ellipsoid, a little inside the true hull, for a cushion).
"""

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ellimann_addon.core.cushion import cushion_mesh, cushion_name
from ellimann_addon.core.ellipsoid import bounds, fibonacci_sphere, sample_surface, support
from ellimann_addon.core.garment_fit import closest_points_on_triangles
from ellimann_addon.core.mannequin import NAME_PATTERN

GRID_SPACING = 0.005  # m: 5 mm resolves fingers and toes; a body is ~0.5 million points
_OFFSET = (0.3719, 0.6143, 0.2281)  # grid origin in cells past the body's corner: no ray on a mesh edge
_BUCKET = 0.01  # m: cell of the triangle index used by the vertical rays
_SURFACE_SAMPLES = 1000  # points per ellipsoid surface, for the depth outside the body
_CUSHION_SUBDIVISIONS = 3  # hull meshes for the metrics (642 support points per ellipsoid)
_NUDGE = (1.3e-7, 0.7e-7)  # m: moves a query line off the mesh edges that lie in the sagittal plane
DEPTH_TIE = 1e-7  # m: depths closer than this are equal (the docs print 0.1 mm; rounding is ~1e-15)
_NEAREST_VERTICES = 4  # the nearest triangle is searched among those around this many nearest vertices

# Each chain is a list of links, each link the labels (names without number and side) of its parts;
# left and central parts only (the mannequins are symmetric). The first link of a limb is where it
# hangs from the trunk.
CHAINS = {
    "leg": [("Pelvis", "Gluteus", "Hip"), ("Thigh",), ("Knee",), ("Calf",), ("Ankle",), ("Foot",), ("Toes",)],
    "arm": [("Deltoid", "Trapezius"), ("Upper Arm",), ("Forearm",), ("Hand",), ("Fingers",)],
    "neck, head": [("Trapezius", "Upper Back", "Thorax"), ("Neck",), ("Cranium", "Face")],
    "trunk, front": [("Thorax", "Breast"), ("Rectus Abdominalis",), ("Pelvis",)],
    "trunk, back": [("Upper Back",), ("Lower Back",), ("Pelvis", "Gluteus")],
    "trunk, side": [("Thorax", "Upper Back"), ("Oblique",), ("Hip",)],
}


class BodyVolume:
    """A closed, outward-wound triangle mesh: inside test by vertical rays, distances to its surface."""

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
        self._tree = cKDTree(self.vertices)
        # up to the largest valence of triangles per vertex, padded with -1
        incident = np.argsort(self.faces.ravel(), kind="stable") // 3
        valence = np.bincount(self.faces.ravel(), minlength=len(self.vertices))
        start = np.cumsum(valence) - valence
        self._ring = np.full((len(self.vertices), valence.max()), -1)
        rank = np.arange(len(incident)) - np.repeat(start, valence)
        self._ring[np.repeat(np.arange(len(self.vertices)), valence), rank] = incident

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

    def distance(self, points):
        """Distance (m) from points (P, 3) to the surface: the nearest of the triangles around the
        nearest vertices (an upper bound of the true distance, equal to it on a fair mesh); and the
        nearest vertex of each point."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        if not len(points):
            return np.zeros(0), np.zeros(0, dtype=int)
        _, near = self._tree.query(points, k=_NEAREST_VERTICES)
        candidates = self._ring[near].reshape(len(points), -1)  # (P, k * valence), -1 padded
        valid = candidates >= 0
        t = self._tri[np.where(valid, candidates, 0)]
        closest = closest_points_on_triangles(points[:, None, :], t[..., 0, :], t[..., 1, :], t[..., 2, :])
        d = np.linalg.norm(closest - points[:, None, :], axis=-1)
        return np.where(valid, d, np.inf).min(axis=1), near[:, 0]

    def grid(self, spacing=GRID_SPACING, margin=0.05):
        """A regular grid around the body with its inside mask (see :class:`Grid`)."""
        lo = self.vertices.min(axis=0) - margin + np.asarray(_OFFSET) * spacing
        shape = np.ceil((self.vertices.max(axis=0) + margin - lo) / spacing).astype(int)
        xs, ys = (lo[k] + spacing * np.arange(shape[k]) for k in (0, 1))
        xy = np.stack(np.meshgrid(xs, ys, indexing="ij"), axis=-1).reshape(-1, 2)
        line, z = self.crossings(xy)
        # a cell is inside when an odd number of crossings lies below it
        first_above = np.clip(np.ceil((z - lo[2]) / spacing).astype(int), 0, shape[2])
        steps = np.zeros((len(xy), shape[2] + 1), dtype=np.int32)
        np.add.at(steps, (line, first_above), 1)
        odd_columns = int(np.count_nonzero(steps.sum(axis=1) % 2))
        if odd_columns:
            raise ValueError(f"{odd_columns} vertical rays cross the body an odd number of times: not a closed mesh")
        inside = (np.cumsum(steps[:, :-1], axis=1) % 2 == 1).reshape(shape)
        return Grid(lo, spacing, inside)


@dataclass
class Grid:
    origin: np.ndarray  # (3,) m, centre of cell (0, 0, 0)
    spacing: float
    inside: np.ndarray  # (nx, ny, nz) bool: the cell's centre is inside the body

    def box(self, lo, hi):
        """Index ranges (slices) and centres of the cells whose centres lie in the box [lo, hi]."""
        first = np.maximum(np.ceil((np.asarray(lo) - self.origin) / self.spacing).astype(int), 0)
        last = np.minimum(np.floor((np.asarray(hi) - self.origin) / self.spacing).astype(int),
                          np.array(self.inside.shape) - 1)
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


def _outside_depth(body, points, cavity=None):
    """Largest distance (m) from the surface of the points outside the body (0 if none), leaving out
    those whose nearest vertex is a ``cavity`` wall (bool per vertex: the mesh's open mouth and eye
    sockets, which a solid head fills)."""
    outside = points[~body.contains(points)]
    distance, nearest = body.distance(outside)
    if cavity is not None:
        distance = distance[~cavity[nearest]]
    return float(distance.max()) if len(distance) else 0.0


def fill_metrics(body, grid, mannequin, cavity=None):
    """{"ellipsoids": ..., "cushions": ...}, each {"coverage", "excess" (shares of volume), "depth"
    (m, largest outside the body but in its cavities, see :func:`_outside_depth`), "deepest" (the
    name of the piece that reaches that far)}."""
    hulls = {indices: _hull(mannequin, indices) for _, indices in pieces(mannequin, True) if len(indices) == 2}
    samples = sample_surface(mannequin.rotation, mannequin.center, mannequin.semi_axes, _SURFACE_SAMPLES)
    depth = {}  # piece name -> depth, for the ellipsoids and for the cushion pieces
    for name, indices in pieces(mannequin):
        depth[name] = _outside_depth(body, samples[indices[0]], cavity)
    cushion_depth = {name: _outside_depth(body, hulls[indices][0], cavity) if len(indices) == 2 else depth[name]
                     for name, indices in pieces(mannequin, True)}
    out = {}
    for key, cushions, depths in (("ellipsoids", False, depth), ("cushions", True, cushion_depth)):
        occupied = occupancy(grid, mannequin, cushions, hulls)
        covered = np.count_nonzero(occupied & grid.inside)
        # mirror twins reach equally deep up to rounding: the first (the left one) within DEPTH_TIE is named
        deepest = next(name for name, d in depths.items() if d >= max(depths.values()) - DEPTH_TIE)
        out[key] = {"coverage": covered / np.count_nonzero(grid.inside),
                    "excess": 1.0 - covered / max(np.count_nonzero(occupied), 1),
                    "depth": depths[deepest], "deepest": deepest}
    return out


def _links(mannequin, chain):
    """Per link of ``chain``: the part indices (left and central parts with those labels)."""
    by_label = {}
    for i, part in enumerate(mannequin.topology):
        if part.side in ("L", "C"):
            by_label.setdefault(NAME_PATTERN.match(part.name).group("label"), []).append(i)
    return [[i for label in link for i in by_label.get(label, [])] for link in chain]


_DIRECTIONS = fibonacci_sphere(4000)


def separation(mannequin, first, second):
    """Distance (m) between the convex hulls of two sets of ellipsoids (part indices), 0 if they meet.

    By the separating hyperplane theorem it is the largest gap, over directions u, between the
    support planes h_first(u) and -h_second(-u); support functions of a hull are the largest of
    its ellipsoids'. The best of ``_DIRECTIONS`` is refined by a local search.
    """
    def gap(u):
        a = support(mannequin.rotation[first, None], mannequin.center[first, None],
                    mannequin.semi_axes[first, None], u).max(axis=0)
        b = support(mannequin.rotation[second, None], mannequin.center[second, None],
                    mannequin.semi_axes[second, None], -u).max(axis=0)
        return -a - b

    values = gap(_DIRECTIONS)
    best = _DIRECTIONS[np.argmax(values)]
    value = values.max()
    step = 0.05
    for _ in range(40):
        tangent = np.linalg.svd(best[None])[2][1:]  # two unit vectors normal to best
        trials = best + step * np.concatenate([tangent, -tangent])
        trials /= np.linalg.norm(trials, axis=1, keepdims=True)
        values = gap(trials)
        if values.max() > value:
            best, value = trials[np.argmax(values)], values.max()
        else:
            step *= 0.5
    return max(float(value), 0.0)


def _gap_between(mannequin, first, second, cushions):
    """Smallest distance (m) between two links (0 if any of their pieces touch or overlap)."""
    piece_of = {}
    for _, indices in pieces(mannequin, cushions):
        for i in indices:
            piece_of[i] = indices
    a = {piece_of[i] for i in first}
    b = {piece_of[i] for i in second}
    if a & b:
        return 0.0
    return min(separation(mannequin, list(pa), list(pb)) for pa in a for pb in b)


def chain_gaps(mannequin, cushions=False):
    """{chain: [gap (m) between each two consecutive links]} over CHAINS."""
    return {name: [_gap_between(mannequin, first, second, cushions)
                   for first, second in zip(links, links[1:]) if first and second]
            for name, links in ((name, _links(mannequin, chain)) for name, chain in CHAINS.items())}


def report(mannequin, body_vertices, body_faces, cavity=None, spacing=GRID_SPACING):
    """All metrics for one mannequin over its body (same coordinates), ellipsoids and cushions:
    {"ellipsoids" | "cushions": {"coverage", "excess", "depth", "deepest" (the piece that reaches
    deepest), "gaps": {chain: [m]}}}. ``cavity``: see
    :func:`_outside_depth`."""
    body = BodyVolume(body_vertices, body_faces)
    out = fill_metrics(body, body.grid(spacing), mannequin, cavity)
    out["ellipsoids"]["gaps"] = chain_gaps(mannequin)
    out["cushions"]["gaps"] = chain_gaps(mannequin, True)
    return out
