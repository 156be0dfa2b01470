"""The skin's field: a signed distance to the pieces (negative inside), their smooth union blended only between
neighbours in the body, sampled finely only near the surface.

Each piece's distance is Quilez's first-order bound for an ellipsoid, k0 (k0 - 1) / k1 with k0 = |q / D|,
k1 = |q / D^2| (q the point in the piece's frame): exact on its surface and along its axes, and within a few
per cent of the Euclidean distance in the few centimetres the blend and the meshing look at. The field is the
plain minimum over all pieces, lowered where two *neighbours* meet by the polynomial smooth minimum of width
``blend``: smin(a, b) = min(a, b) - k h^2 / 4, h = max(k - |a - b|, 0) / k. It never raises the field, so the
skin holds every piece, and it adds at most k / 4 where two surfaces cross. Pieces that are not neighbours (an
arm beside the torso, the two thighs, a hand at the hip) meet in a plain crease, with no webbing; where they do
not touch but come nearer than the skin's gap (a voxel and a quarter) and one of them is off the trunk (a limb, the
head), each is cut back from the other to half the gap (``apart_pairs``): a voxel would otherwise join them, and an
arm joined to the flank below the shoulder it hangs from makes a handle through the body. The trunk's pieces are
one body: a gap between two of them (the left and right trapezius under the neck) would open a tunnel.

Sampling: the field on a coarse grid (``COARSE`` times the spacing) decides which coarse cells can hold the
surface (some corner nearer than the cell's reach); only their nodes are sampled at half the spacing, which
decides the same for its cells, down to the spacing asked for; the others take their cell's sign. The meshing
gets the same values it would from the whole grid.
"""

from dataclasses import dataclass

import numpy as np

from ..geometry.ellipsoid import bounds, sample_surface
from ..mannequin.skeleton import PARENTS, bone_problems, part_bones

COARSE = 4  # fine nodes per coarse cell edge (a power of 2)
LIPSCHITZ = 1.5  # bound on the field's slope used to rule a coarse cell out (the bound's slope is 1 at a surface)
FAR = 1.0  # m: the value of fine nodes no piece is near (only its sign is used)
POWER = 4.0
ONSET = 1.0  # times the fillet's depth: the span over which a fillet's emergence is rounded
# A pair's blend fades out as the farther piece gets between FULL and FADE widths away. Near the surface the
# blend only counts where the nearer piece is within a quarter width of it and the two within a width of each
# other (farther piece < 1.25 widths): up to FULL it is whole; beyond FADE nothing needs a piece's distance.
FULL, FADE = 1.25, 1.5
MAX_BLEND = 0.04  # m: the widest blend (the trunk's big pieces)
# The regions off the trunk: a piece of one may be kept apart from others. The trunk's (neck, shoulders, chest,
# abdomen, hips) are one body, and a region of one's own topology the skin does not know is taken as the trunk's.
OFF_TRUNK_REGIONS = frozenset(("head", "arms", "hands", "legs", "feet"))
# Pieces that do not touch are kept this many voxels apart: a 6-connected mesh separates two insides when every
# grid line between them meets an outside node, which a gap of a voxel holds; the rest is the distances' slack.
GAP = 1.25
SURFACE_SAMPLES = 512  # points on a piece's surface by which apart_pairs judges whether two pieces touch


@dataclass(frozen=True)
class Grid:
    """Nodes origin + spacing * (i, j, k) for 0 <= (i, j, k) < shape."""

    origin: np.ndarray
    spacing: object  # m: one for every axis, or (3,)
    shape: tuple

    @property
    def size(self):
        return int(np.prod(self.shape))

    def points(self, flat):
        """Positions (k, 3) of flat node indices."""
        return self.origin + self.spacing * np.stack(np.unravel_index(flat, self.shape), axis=1)


def piece_distance(points, rotation, center, semi_axes):
    """Signed distance bound (k,) of ``points`` (k, 3) to one ellipsoid: negative inside, exact on its surface."""
    scaled = (points - center) @ (rotation / semi_axes)  # q / D, q the point in the ellipsoid's frame
    k0 = np.sqrt(np.einsum("ij,ij->i", scaled, scaled))
    scaled /= semi_axes
    k1 = np.sqrt(np.einsum("ij,ij->i", scaled, scaled))
    with np.errstate(divide="ignore", invalid="ignore"):
        distance = k0 * (k0 - 1.0) / k1
    # no point of an ellipsoid is deeper than its smallest semi-axis: the bound's steep dive near the centre
    # (towards minus the largest one) is cut there
    deepest = -semi_axes.min()
    return np.maximum(np.where(k1 > 0.0, distance, deepest), deepest)


def blend_amount(a, b, width):
    """How far the polynomial smooth minimum of width ``width`` lies below min(a, b): up to width / 4 where they
    are equal, 0 from |a - b| = width on (where it joins the minimum with a continuous slope)."""
    h = np.maximum(width - np.abs(a - b), 0.0) / width
    return h * h * width * 0.25


def _soft_positive(x, scale):
    """max(x, 0) with its corner rounded over +-scale (a parabola there): where a fillet comes out from under
    a third piece the surface bends instead of creasing."""
    with np.errstate(divide="ignore", invalid="ignore"):
        rounded = (x + scale) ** 2 / (4.0 * scale)
    return np.where(x >= scale, x, np.where(x <= -scale, 0.0, rounded))


def _smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


# Regions of a topology that touch in a body (each also touches itself): pieces of touching regions blend.
REGION_NEIGHBOURS = {
    frozenset(pair)
    for pair in (
        ("head", "neck"),
        ("neck", "shoulders"),
        ("neck", "chest"),
        ("shoulders", "chest"),
        ("shoulders", "arms"),
        ("arms", "hands"),
        ("chest", "abdomen"),
        ("abdomen", "hips"),
        ("hips", "legs"),
        ("legs", "feet"),
    )
}


def blend_pairs(topology):
    """(P, 2) part indices that blend: neighbours in the body. Two parts are neighbours when they are cushion
    partners, or ride on one bone or on a bone and its child, or belong to one region or to two regions that
    touch (REGION_NEIGHBOURS: the shoulder's pieces with the chest's, not the arm's); never a left part with a
    right one (the thighs, the breasts, the buttocks meet in a crease) nor an arm with the torso beside it. A
    topology whose parts are not all on a bone (a reference set of one's own, with its own labels) blends by
    partners and regions alone."""
    bones = None if bone_problems(topology) else part_bones(topology)
    partners = {tuple(sorted(pair)) for pair in topology.cushion_pairs}
    parts = list(topology)

    def neighbours(i, j):
        a, b = parts[i], parts[j]
        if {a.side, b.side} == {"L", "R"}:
            return False
        joined = bones is not None and (
            bones[i] == bones[j] or PARENTS[bones[i]] == bones[j] or PARENTS[bones[j]] == bones[i]
        )
        return (
            (i, j) in partners or joined or a.region == b.region or frozenset((a.region, b.region)) in REGION_NEIGHBOURS
        )

    pairs = [(i, j) for i in range(len(parts)) for j in range(i + 1, len(parts)) if neighbours(i, j)]
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)


def blend_widths(semi_axes, pairs, blend):
    """(P,) m: each pair's blend width, ``blend`` times the thinner piece's smallest semi-axis (fingers blend over
    millimetres, the torso's pieces over centimetres)."""
    thinnest = np.asarray(semi_axes).min(axis=1)
    return np.minimum(blend * np.minimum(thinnest[pairs[:, 0]], thinnest[pairs[:, 1]]), MAX_BLEND)


def apart_pairs(rotation, center, semi_axes, pairs, widths, gap, off_trunk):
    """(S, 2) part indices that do not blend (not in ``pairs``), not both on the trunk (``off_trunk``: a bool per
    part), do not touch, and come nearer than ``gap`` plus how far their fillets with others may bulge (a quarter of
    their widest blend ``widths`` each): the skin keeps them ``gap`` apart. Touching is judged on SURFACE_SAMPLES
    points of each piece's surface, by the other's distance bound there (an overlap under a millimetre between
    the samples may be missed: those pieces are then cut apart by that much more)."""
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    bulge = np.zeros(len(center))
    for (i, j), width in zip(pairs, widths):
        bulge[[i, j]] = np.maximum(bulge[[i, j]], 0.25 * width)
    lo, hi = bounds(rotation, center, semi_axes)
    reach = gap + bulge[:, None] + bulge[None, :]
    near = np.all(
        (lo[:, None] <= hi[None, :] + reach[..., None]) & (lo[None, :] <= hi[:, None] + reach[..., None]), axis=2
    )
    near[pairs[:, 0], pairs[:, 1]] = near[pairs[:, 1], pairs[:, 0]] = False
    near &= np.logical_or.outer(off_trunk, off_trunk)
    surface = sample_surface(rotation, center, semi_axes, SURFACE_SAMPLES)
    apart = []
    for i, j in zip(*np.nonzero(np.triu(near, 1))):
        nearest = min(
            piece_distance(surface[i], rotation[j], center[j], semi_axes[j]).min(),
            piece_distance(surface[j], rotation[i], center[i], semi_axes[i]).min(),
        )
        if 0.0 < nearest < reach[i, j]:
            apart.append((i, j))
    return np.array(apart, dtype=np.int64).reshape(-1, 2)


def field_grid(rotation, center, semi_axes, spacing, blend):
    """The fine grid around the pieces: a margin of the widest blend and two cells, whole coarse cells on every
    axis."""
    lo, hi = bounds(rotation, center, semi_axes)
    margin = blend + 2.0 * spacing
    lo, hi = lo.min(axis=0) - margin, hi.max(axis=0) + margin
    cells = np.ceil((hi - lo) / (spacing * COARSE)).astype(int)
    return Grid(lo, float(spacing), tuple(int(n) for n in cells * COARSE + 1))


def skin_pieces(mannequin, blend, voxel):
    """The PieceField of ``mannequin``'s skin at ``blend`` meshed at ``voxel`` (m): neighbours blended
    (``blend_pairs``), pieces that do not touch kept GAP voxels apart (``apart_pairs``)."""
    arrays = (mannequin.rotation, mannequin.center, mannequin.semi_axes)
    pairs = blend_pairs(mannequin.topology)
    widths = blend_widths(mannequin.semi_axes, pairs, blend)
    off_trunk = np.array([part.region in OFF_TRUNK_REGIONS for part in mannequin.topology])
    gap = GAP * voxel
    return PieceField(*arrays, pairs, widths, apart_pairs(*arrays, pairs, widths, gap, off_trunk), gap)


class PieceField:
    """The pieces' arrays and padded boxes, and the field on the marked nodes of a grid."""

    def __init__(self, rotation, center, semi_axes, pairs, widths, apart=None, gap=0.0):
        self.rotation, self.center, self.semi_axes = rotation, center, semi_axes
        self.pairs, self.widths = pairs, widths
        self.apart, self.gap = (np.zeros((0, 2), dtype=np.int64) if apart is None else apart), gap
        self.lo, self.hi = bounds(rotation, center, semi_axes)
        self.margin = np.zeros(len(center))  # each piece's widest blend
        for (i, j), width in zip(pairs, widths):
            self.margin[[i, j]] = np.maximum(self.margin[[i, j]], width)
        # how far out each piece's distances are needed: as far as its fillets fade out, and for a piece kept apart
        # as far as its partner's fillets may still be held back by it (its lift above -gap / 2, see _combine)
        self.extent = FADE * self.margin
        for i, j in self.apart:
            self.extent[j] = max(self.extent[j], 2.0 * gap + FADE * self.margin[i])
            self.extent[i] = max(self.extent[i], 2.0 * gap + FADE * self.margin[j])

    def without_gaps(self):
        """This field with no pieces kept apart."""
        return PieceField(self.rotation, self.center, self.semi_axes, self.pairs, self.widths)

    def distance(self, i, points):
        return piece_distance(points, self.rotation[i], self.center[i], self.semi_axes[i])

    def subset(self, keep):
        """(the field of the pieces ``keep`` (indices) and the pairs among them, their indices here): the same
        field wherever the others are too far to count."""
        keep = np.asarray(keep)
        index = np.full(len(self.center), -1)
        index[keep] = np.arange(len(keep))
        among = (index[self.pairs[:, 0]] >= 0) & (index[self.pairs[:, 1]] >= 0)
        apart = self.apart[(index[self.apart[:, 0]] >= 0) & (index[self.apart[:, 1]] >= 0)]
        arrays = (self.rotation[keep], self.center[keep], self.semi_axes[keep])
        pieces = PieceField(*arrays, index[self.pairs[among]], self.widths[among], index[apart], self.gap)
        return pieces, keep

    def field(self, grid, marked, reach):
        """The field (grid.shape) on the ``marked`` nodes where a piece comes within ``reach``, FAR elsewhere;
        and the nearest piece of each node (flat, -1 where none is near or not marked)."""
        nodes = np.flatnonzero(marked)
        found, nearest = self.sampled(grid, marked, nodes, reach)
        values = np.full(grid.size, FAR)
        values[nodes] = found
        nearest_piece = np.full(grid.size, -1, dtype=np.int32)
        nearest_piece[nodes] = nearest
        return values.reshape(grid.shape), nearest_piece

    def sampled(self, grid, marked, nodes, reach):
        """The field and the nearest piece at the ``marked`` nodes of ``grid`` only, given as ``nodes`` (their
        flat indices, ascending): two arrays as long as ``nodes``."""
        slot = np.full(grid.size, -1, dtype=np.int64)
        slot[nodes] = np.arange(len(nodes))

        def select(lo, hi):
            flat, points = _box_nodes(grid, marked, lo, hi)
            return slot[flat], points

        return self._combine(len(nodes), select, reach)

    def at(self, points, reach):
        """The field at ``points`` (k, 3) where a piece comes within ``reach`` (FAR elsewhere), and the nearest
        piece of each (-1 where none is near): for a few scattered points (every box is a mask over them)."""

        order = np.argsort(points[:, 0], kind="stable")  # _combine needs the nodes' x to ascend with them
        ordered = points[order]

        def inside(lo, hi):
            rows = np.flatnonzero(np.all((ordered >= lo) & (ordered <= hi), axis=1))
            return rows, ordered[rows]

        values, nearest = self._combine(len(points), inside, reach)
        back = np.empty_like(order)
        back[order] = np.arange(len(order))
        return values[back], nearest[back]

    def _combine(self, size, select, reach):
        """The field on ``size`` nodes, those in a box given by ``select(lo, hi)`` -> (ascending nodes, points);
        the nodes' x must ascend with them (a grid's flat order, or points sorted by x)."""
        near = []  # each piece's nodes (ascending), their points and its distances there
        for i in range(len(self.center)):
            margin = self.extent[i] + reach
            nodes, points = select(self.lo[i] - margin, self.hi[i] + margin)
            near.append((nodes, points, self.distance(i, points)))
        # A piece apart from another is lifted to half the gap on their bisector: lift = (gap + d_i - d_j) / 2,
        # the most over its partners (-inf where none is near); its distance is cut to max(d, lift), and no fillet
        # of it with a third piece reaches below its lift where the lift is above 0 (so the gap stays open), eased
        # off to nothing by -gap / 2 (below 0 the fillet's sign is the same either way: only the gap is touched).
        lift = [None] * len(near)
        for i, j in self.apart:
            rows_i, rows_j = _shared(near[i], near[j])
            a, b = near[i][2][rows_i], near[j][2][rows_j]
            for piece, rows, value in ((i, rows_i, 0.5 * (self.gap + a - b)), (j, rows_j, 0.5 * (self.gap + b - a))):
                if lift[piece] is None:
                    lift[piece] = np.full(len(near[piece][0]), -np.inf)
                lift[piece][rows] = np.maximum(lift[piece][rows], value)
        near = [(n, p, d if up is None else np.maximum(d, up)) for (n, p, d), up in zip(near, lift)]
        flat = np.full(size, FAR)
        nearest_piece = np.full(size, -1, dtype=np.int32)
        for i, (nodes, _, distance) in enumerate(near):
            current = flat[nodes]
            closer = distance < current
            nearest_piece[nodes[closer]] = i
            flat[nodes] = np.where(closer, distance, current)
        nearest = flat.copy()  # the plain minimum over every piece
        # Each pair's fillet (the polynomial smooth minimum's) reaches below the plain minimum by some depth; the
        # pairs' depths are joined by a POWER-norm: their maximum where one pair blends, smooth where two meet.
        power = np.zeros_like(flat)
        for (i, j), width in zip(self.pairs, self.widths):
            if width <= 0.0:  # a plain union
                continue
            rows_i, rows_j = _shared(near[i], near[j])
            a, b = near[i][2][rows_i], near[j][2][rows_j]
            blending = np.abs(a - b) < width  # elsewhere the fillet is nil
            rows_i, rows_j = rows_i[blending], rows_j[blending]
            nodes, a, b = near[i][0][rows_i], a[blending], b[blending]
            # faded out between FULL and FADE widths from the farther piece, so that the field stays
            # continuous where the nodes whose distances are known end
            fade = _smoothstep((FADE * width - np.maximum(a, b)) / ((FADE - FULL) * width))
            lowered = fade * blend_amount(a, b, width)
            for piece, rows in ((i, rows_i), (j, rows_j)):
                if lift[piece] is not None:  # not into a gap
                    up = lift[piece][rows]
                    held = np.minimum(lowered, np.maximum(np.minimum(a, b) - up, 0.0))
                    lowered += _smoothstep((up + 0.5 * self.gap) / (0.5 * self.gap)) * (held - lowered)
            # how far the pair's fillet reaches below the front; its onset rounded over a span that vanishes
            # with the fillet, so that a pair whose pieces do not meet adds nothing
            reach_below = _soft_positive(lowered - (np.minimum(a, b) - nearest[nodes]), ONSET * lowered)
            power[nodes] += reach_below**POWER
        flat -= power ** (1.0 / POWER)
        return flat, nearest_piece


def _shared(near_i, near_j):
    """The rows of the nodes two pieces' lists (nodes ascending, points, distances) both hold: (rows in i's,
    rows in j's). Searched among the shorter list's nodes within the longer's x range (x ascends with the
    nodes)."""
    swap = len(near_j[0]) < len(near_i[0])
    (nodes_i, points_i, _), (nodes_j, points_j, _) = (near_j, near_i) if swap else (near_i, near_j)
    if not len(nodes_j):
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    first = np.searchsorted(points_i[:, 0], points_j[0, 0], side="left")
    last = np.searchsorted(points_i[:, 0], points_j[-1, 0], side="right")
    candidates = nodes_i[first:last]
    position = np.minimum(np.searchsorted(nodes_j, candidates), len(nodes_j) - 1)
    shared = np.flatnonzero(nodes_j[position] == candidates)
    rows_i, rows_j = first + shared, position[shared]
    return (rows_j, rows_i) if swap else (rows_i, rows_j)


def _box_nodes(grid, marked, lo, hi):
    """The marked nodes of ``grid`` in the box [lo, hi]: flat indices (k,) and positions (k, 3)."""
    start = np.clip(np.ceil((lo - grid.origin) / grid.spacing).astype(int), 0, grid.shape)
    stop = np.clip(np.floor((hi - grid.origin) / grid.spacing).astype(int) + 1, 0, grid.shape)
    if np.any(stop <= start):
        return np.zeros(0, dtype=np.int64), np.zeros((0, 3))
    local = np.nonzero(marked[start[0] : stop[0], start[1] : stop[1], start[2] : stop[2]])
    index = tuple(axis + offset for axis, offset in zip(local, start))
    return np.ravel_multi_index(index, grid.shape), grid.origin + grid.spacing * np.stack(index, axis=1)


def sample_field(pieces, spacing):
    """The field of ``pieces`` (a PieceField) on the fine grid: (values (nx, ny, nz), Grid, the nearest piece of
    each node (flat, -1: none near)). Levels from COARSE times the spacing down, each half the last: a level samples
    only the nodes of the cells the level above found the surface may cross; the other nodes hold +-FAR (their
    cell's sign)."""
    blend = FADE * max(pieces.widths, default=0.0)
    grid = field_grid(pieces.rotation, pieces.center, pieces.semi_axes, spacing, blend)
    step = COARSE
    level = Grid(grid.origin, spacing * step, tuple((n - 1) // step + 1 for n in grid.shape))
    marked = np.ones(level.shape, dtype=bool)
    sign = np.ones(level.shape)  # the sign of the nodes not sampled (none at the coarsest level)
    while True:
        nodes = np.flatnonzero(marked)
        # LIPSCHITZ * sqrt(3) * spacing: the most a node beside a crossing can hold
        found, nearest = pieces.sampled(level, marked, nodes, LIPSCHITZ * np.sqrt(3.0) * level.spacing)
        values = sign * FAR
        values.reshape(-1)[nodes] = found
        if step == 1:
            nearest_piece = np.full(grid.size, -1, dtype=np.int32)
            nearest_piece[nodes] = nearest
            return values, grid, nearest_piece
        active, inside = _crossable_cells(values, LIPSCHITZ * np.sqrt(3.0) / 2.0 * level.spacing)
        step //= 2
        level = Grid(grid.origin, spacing * step, tuple((n - 1) // step + 1 for n in grid.shape))
        marked = _cell_nodes(_halved(active))
        sign = np.where(_halved(inside), -1.0, 1.0)


def _crossable_cells(values, reach):
    """(cells the surface may cross: a corner nearer than ``reach`` (a crossing lies that near a corner of its
    cell) or corners of both signs; each cell's sign, its first corner's)."""
    nx, ny, nz = values.shape
    near = np.abs(values) < reach
    inside = values[:-1, :-1, :-1] < 0.0
    active = np.zeros((nx - 1, ny - 1, nz - 1), dtype=bool)
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                corner = (slice(dx, nx - 1 + dx), slice(dy, ny - 1 + dy), slice(dz, nz - 1 + dz))
                active |= near[corner] | ((values[corner] < 0.0) != inside)
    return active, inside


def _halved(cells):
    """Cells (a, b, c) as the cells of half their size they hold, plus one node layer: (2a + 1, 2b + 1, 2c + 1)."""
    fine = cells.repeat(2, axis=0).repeat(2, axis=1).repeat(2, axis=2)
    return np.pad(fine, ((0, 1), (0, 1), (0, 1)), mode="edge")


def _cell_nodes(cells):
    """Nodes that are a corner of a marked cell (``cells`` padded by one node layer, as ``_halved`` gives)."""
    nodes = cells.copy()
    nodes[1:] |= cells[:-1]
    nodes[:, 1:] |= nodes[:, :-1].copy()
    nodes[:, :, 1:] |= nodes[:, :, :-1].copy()
    return nodes
