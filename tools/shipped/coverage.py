"""How well a mannequin fills the body it was traced from: the product's coverage and excess
(core/geometry/volume.py), plus what only the build's docs print: depth and gaps along the limbs.

- **coverage**, **excess**: see ``ellimann_addon.core.geometry.volume``;
- **depth**: how far (m) a piece reaches outside the body surface at most (leaving out the mesh's open
  mouth and eye sockets, if given);
- **gaps**: along each chain of CHAINS (e.g. thigh, knee, calf, ankle, foot, toes), the distance
  between each two consecutive links (0 where they touch or overlap).
"""

import numpy as np
from scipy.spatial import cKDTree

from ellimann_addon.core.drape.fit_metrics import closest_points_on_triangles
from ellimann_addon.core.geometry import volume
from ellimann_addon.core.geometry.ellipsoid import fibonacci_sphere, sample_surface, support
from ellimann_addon.core.geometry.volume import GRID_SPACING, fill_shares, occupancy, pieces
from ellimann_addon.core.mannequin.topology import NAME_PATTERN

__all__ = ["GRID_SPACING", "BodyVolume", "CHAINS", "chain_gaps", "fill_metrics", "occupancy", "report", "separation"]

_SURFACE_SAMPLES = 1000  # points per ellipsoid surface, for the depth outside the body
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


class BodyVolume(volume.BodyVolume):
    """The product's body volume (inside tests, grids) with distances to its surface."""

    def __init__(self, vertices, faces):
        super().__init__(vertices, faces)
        self._tree = cKDTree(self.vertices)
        # up to the largest valence of triangles per vertex, padded with -1
        incident = np.argsort(self.faces.ravel(), kind="stable") // 3
        valence = np.bincount(self.faces.ravel(), minlength=len(self.vertices))
        start = np.cumsum(valence) - valence
        self._ring = np.full((len(self.vertices), valence.max()), -1)
        rank = np.arange(len(incident)) - np.repeat(start, valence)
        self._ring[np.repeat(np.arange(len(self.vertices)), valence), rank] = incident

    def nearest_vertex(self, points):
        """Index of the body vertex nearest each point (P, 3)."""
        return self._tree.query(np.asarray(points, dtype=float).reshape(-1, 3))[1]

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


def _outside_depth(body, points, cavity=None):
    """Largest distance (m) from the surface of the points outside the body (0 if none), leaving out
    those whose nearest vertex is a ``cavity`` wall (bool per vertex: the mesh's open mouth and eye
    sockets, which a solid head fills)."""
    outside = points[~body.contains(points)]
    distance, nearest = body.distance(outside)
    if cavity is not None:
        distance = distance[~cavity[nearest]]
    return float(distance.max()) if len(distance) else 0.0


def _hollow(body, grid, mannequin, hulls, cavity):
    """Bool over the grid: the cells outside the body, inside a piece, whose nearest body vertex is a ``cavity`` wall
    (the mesh's open mouth and eye sockets, which a solid head fills)."""
    outside = occupancy(grid, mannequin, True, hulls) & ~grid.inside  # the cushions hold the ellipsoids
    cells = np.argwhere(outside)
    nearest = body.nearest_vertex(grid.origin + grid.spacing * cells)
    hollow = np.zeros_like(outside)
    hollow[tuple(cells[cavity[nearest]].T)] = True
    return hollow


def fill_metrics(body, grid, mannequin, cavity=None):
    """{"ellipsoids": ..., "cushions": ...}, each {"coverage", "excess" (shares of volume, core.geometry.volume; the
    mesh's open mouth and eye sockets, ``cavity``, are no excess: a solid head fills them), "depth" (m, largest
    outside the body but in its cavities, see :func:`_outside_depth`), "deepest" (the name of the piece that reaches
    that far)}."""
    hulls = volume.cushion_hulls(mannequin)
    samples = sample_surface(mannequin.rotation, mannequin.center, mannequin.semi_axes, _SURFACE_SAMPLES)
    depth = {}  # piece name -> depth, for the ellipsoids and for the cushion pieces
    for name, indices in pieces(mannequin):
        depth[name] = _outside_depth(body, samples[indices[0]], cavity)
    cushion_depth = {
        name: _outside_depth(body, hulls[indices][0], cavity) if len(indices) == 2 else depth[name]
        for name, indices in pieces(mannequin, True)
    }
    out = fill_shares(grid, mannequin, hulls, None if cavity is None else _hollow(body, grid, mannequin, hulls, cavity))
    for key, depths in (("ellipsoids", depth), ("cushions", cushion_depth)):
        # mirror twins reach equally deep up to rounding: the first (the left one) within DEPTH_TIE is named
        deepest = next(name for name, d in depths.items() if d >= max(depths.values()) - DEPTH_TIE)
        out[key].update(depth=depths[deepest], deepest=deepest)
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
        a = support(
            mannequin.rotation[first, None], mannequin.center[first, None], mannequin.semi_axes[first, None], u
        ).max(axis=0)
        b = support(
            mannequin.rotation[second, None], mannequin.center[second, None], mannequin.semi_axes[second, None], -u
        ).max(axis=0)
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


def chain_gaps(mannequin, cushions=False, chains=CHAINS):
    """{chain: [gap (m) between each two consecutive links]} over ``chains`` (default: CHAINS, the 40's)."""
    return {
        name: [
            _gap_between(mannequin, first, second, cushions)
            for first, second in zip(links, links[1:])
            if first and second
        ]
        for name, links in ((name, _links(mannequin, chain)) for name, chain in chains.items())
    }


def report(mannequin, body_vertices, body_faces, cavity=None, spacing=GRID_SPACING, chains=CHAINS):
    """All metrics for one mannequin over its body (same coordinates), ellipsoids and cushions:
    {"ellipsoids" | "cushions": {"coverage", "excess", "depth", "deepest" (the piece that reaches
    deepest), "gaps": {chain: [m]}}}. ``cavity``: see :func:`_outside_depth`; ``chains``: see
    :func:`chain_gaps`."""
    body = BodyVolume(body_vertices, body_faces)
    out = fill_metrics(body, body.grid(spacing), mannequin, cavity)
    out["ellipsoids"]["gaps"] = chain_gaps(mannequin, chains=chains)
    out["cushions"]["gaps"] = chain_gaps(mannequin, True, chains)
    return out
