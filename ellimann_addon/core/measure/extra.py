"""The measurements beyond the paper's five: names, labels, where each is taken, and their closed forms on a
mannequin's ellipsoids (``docs/measurements.md``; a body mesh is measured the same way by ``core.measure.body``).

Landmarks shared by both (A-pose, the body faces -Y, +X its left, Z up; fractions of He above the soles):
- the mid-plane x_c: the middle of the body's x extent at 0.25 He (the calves: no hand hangs that low);
- the crotch: the lowest point of the body on the plane x = x_c above 0.2 He (below it every section of
  the legs lies wholly left or right of x_c);
- the shoulder point of each side: the outermost point of the Sh section (at the set's Sh height);
- the fingertip: the point of the arm farthest from its shoulder point.
Measurements (cm):
- crotch_height: the crotch's height (the inside leg);
- thigh: one leg's girth at ``THIGH_DROP`` He below the crotch (the gluteal fold);
- calf: the largest girth of one leg between ``CALF_BAND`` of the crotch height;
- neck: the smallest girth of the whole section between ``NECK_BAND`` He (the neck, wherever jaw and shoulders are);
- arm_length: shoulder point to fingertip (straight, the arm as it hangs in the A-pose);
- upper_arm: the arm's girth across its axis (shoulder point to fingertip) at ``UPPER_ARM_FRACTION`` of it.
A girth is the perimeter of the convex hull of a section (a tape measure), as m_T's; both legs or arms are
measured and their mean reported.
"""

import numpy as np

from ..constants import CM_PER_M, MEASUREMENTS
from ..geometry.ellipsoid import axis_extent, section_at_height
from .tailor import hull_perimeter, section_heights

EXTRA_MEASUREMENTS = ("neck", "upper_arm", "thigh", "calf", "crotch_height", "arm_length")
EXTRA_LABELS = {
    "neck": "Neck girth",
    "upper_arm": "Upper-arm girth",
    "thigh": "Thigh girth",
    "calf": "Calf girth",
    "crotch_height": "Crotch height",
    "arm_length": "Arm length",
}
EXTRA_GIRTHS = ("neck", "upper_arm", "thigh", "calf")
# Plausibility limits (cm) of a request, as ABSURD_LIMITS for the five.
EXTRA_ABSURD_LIMITS = {
    "neck": (15.0, 80.0),
    "upper_arm": (10.0, 80.0),
    "thigh": (20.0, 140.0),
    "calf": (15.0, 90.0),
    "crotch_height": (20.0, 130.0),
    "arm_length": (20.0, 120.0),
}
# What the female Average Reference Mannequin measures (cm): the panel's starting values.
EXTRA_DEFAULTS = {
    "neck": 32.4,
    "upper_arm": 23.6,
    "thigh": 56.0,
    "calf": 42.6,
    "crotch_height": 72.0,
    "arm_length": 57.8,
}
# ISO 20685 allowances (cm): how far two ways of measuring one body may differ.
ISO_ALLOWANCE = {
    "He": 0.4,
    "Sh": 0.4,
    "Br": 0.9,
    "Wa": 0.9,
    "Hi": 0.9,
    "neck": 0.9,
    "upper_arm": 0.9,
    "thigh": 0.9,
    "calf": 0.9,
    "crotch_height": 0.4,
    "arm_length": 0.4,
}

MID_PLANE_HEIGHT = 0.25  # He: where x_c is taken
CROTCH_FLOOR = 0.2  # He: the crotch is searched above this
THIGH_DROP = 0.02  # He below the crotch
CALF_BAND = (0.25, 0.6)  # fractions of the crotch height
NECK_BAND = (0.80, 0.92)  # fractions of He
UPPER_ARM_FRACTION = 0.25  # of the shoulder-to-fingertip axis, from the shoulder
BAND_SAMPLES = 48  # grid over a band before the extreme is refined
GOLDEN_STEPS = 40  # golden-section steps: the band's grid cell shrinks below a micrometre
BRACKET_DONE = 3e-9  # m: a smooth band search's bracket this narrow is done (a girth within nanometres)
PROBE_FLOOR = 1e-9  # m: the closest spacing of a smooth search's parabolic probes
END_PROBE = 1e-10  # m: how far beside a piece's end a smooth search looks (the limit there)
PROBES_PER_STEP = 24  # a smooth search's probes per call, shared among the brackets still open
MAX_PROBE_PAIRS = 3
MAX_BRACKET_STEPS = 60  # a smooth search's bound (halving from a cell: some 25 steps at worst)
GIRTH_CHUNK = 48  # sections per hull_perimeter call
SIDES = ("L", "R")


def _band_grid(low, high, breaks, samples):
    """The band [low, high] cut at ``breaks`` and each piece sampled on a grid: (pieces, per piece)."""
    cuts = np.unique(np.clip(np.concatenate([[low, high], np.asarray(breaks, float)]), low, high))
    per_piece = max(4, samples // max(len(cuts) - 1, 1))
    t = np.linspace(0.0, 1.0, per_piece)
    return cuts[:-1, None] + (cuts[1:] - cuts[:-1])[:, None] * t


def _best_cells(grid, values):
    """Per piece: its best sample (smallest value) and the samples either side, clipped at the piece's ends:
    (a, x, b) heights and (fa, fx, fb) values."""
    best = np.argmin(values, axis=1)
    rows, last = np.arange(len(grid)), grid.shape[1] - 1
    around = [np.maximum(best - 1, 0), best, np.minimum(best + 1, last)]
    return [grid[rows, i] for i in around], [values[rows, i] for i in around]


def extreme_over_band(function, low, high, largest, breaks=(), samples=BAND_SAMPLES, where=False):
    """Largest (or smallest) value of a 1-D ``function`` (vectorised over an array of heights) on [low, high].

    The band is cut at ``breaks`` (where the function may have a kink or a narrow dip: the ends of the pieces
    a mannequin's section meets) and each piece sampled on a grid; golden-section search then refines every
    grid cell beside a piece's best sample, all pieces at once, and the best of everything is returned. For a
    function with kinks anywhere (a mesh's girths); a smooth one is refined faster by :func:`extremes_over_bands`."""
    grid = _band_grid(low, high, breaks, samples)
    sign = -1.0 if largest else 1.0
    values = sign * function(grid.ravel()).reshape(grid.shape)
    (a, _, b), _ = _best_cells(grid, values)
    ratio = (np.sqrt(5.0) - 1.0) / 2.0
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = sign * function(c), sign * function(d)
    for _ in range(GOLDEN_STEPS):
        left = fc < fd  # the minimum of sign * f lies in [a, d]
        a, b = np.where(left, a, c), np.where(left, d, b)
        c_new, d_new = np.where(left, b - ratio * (b - a), d), np.where(left, c, a + ratio * (b - a))
        probe = np.where(left, c_new, d_new)
        fp = sign * function(probe)
        fc, fd = np.where(left, fp, fd), np.where(left, fc, fp)
        c, d = c_new, d_new
    heights = np.concatenate([grid.ravel(), c, d])
    found = np.concatenate([values.ravel(), fc, fd])
    best_index = int(np.argmin(found))
    value = float(sign * found[best_index])
    return (value, float(heights[best_index])) if where else value


def extremes_over_bands(evaluate, bands, points=(), samples=BAND_SAMPLES):
    """The extreme of each band of a function smooth between its breaks, all bands refined together.

    ``evaluate(family, heights)``: values at arrays of (family index, height); ``bands``: (family, low, high,
    largest, breaks) each; ``points``: (family, height) pairs evaluated with the grids (one call for both).
    Each band is gridded as :func:`extreme_over_band` grids it and the cell beside each piece's best sample
    refined by steps of a few probes per bracket in one call (:func:`_probes`: a piece's end checked, the
    parabola's vertex, even cuts where a step did not halve the bracket) until it is BRACKET_DONE wide.
    Between breaks a girth is smooth but for kinks, so a bracket closes in a handful of steps instead of golden
    section's 40. Returns (the extremes [float], the values at ``points`` (p,))."""
    grids = [_band_grid(low, high, breaks, samples) for _, low, high, _, breaks in bands]
    signs = np.array([-1.0 if band[3] else 1.0 for band in bands])
    band_of_sample = np.concatenate([np.full(grid.size, i) for i, grid in enumerate(grids)]).astype(int)
    families = np.array([band[0] for band in bands], int)
    point_family = np.array([family for family, _ in points], int)
    point_height = np.array([height for _, height in points], float)
    values = evaluate(
        np.concatenate([families[band_of_sample], point_family]),
        np.concatenate([grid.ravel() for grid in grids] + [point_height]),
    )
    grid_values, at_points = values[: len(band_of_sample)] * signs[band_of_sample], values[len(band_of_sample) :]
    cells, start = [], 0
    for grid in grids:
        cells.append(_best_cells(grid, grid_values[start : start + grid.size].reshape(grid.shape)))
        start += grid.size
    heights = [np.concatenate([c[0][j] for c in cells]) for j in range(3)]
    fvalues = [np.concatenate([c[1][j] for c in cells]) for j in range(3)]
    band_of = np.concatenate([np.full(len(grid), i) for i, grid in enumerate(grids)]).astype(int)
    ends = [np.concatenate([grid[:, j] for grid in grids]) for j in (0, -1)]
    best = _refine_brackets(
        lambda rows, z: signs[band_of[rows]] * evaluate(families[band_of[rows]], z), heights, fvalues, ends
    )
    extremes = []
    for i in range(len(bands)):
        found = np.concatenate([grid_values[band_of_sample == i], best[band_of == i]])
        extremes.append(float(signs[i] * found.min()) if len(found) else np.nan)
    return extremes, at_points


def _refine_brackets(evaluate, heights, values, ends):
    """Smallest value in each bracket (a, x, b) (fa, fx, fb) with fx <= fa, fb, by parabolic steps
    (:func:`extremes_over_bands`); ``ends``: the (lowest, highest) height of each bracket's piece;
    ``evaluate(rows, heights)`` gives the values of brackets ``rows``."""
    (a, x, b), (fa, fx, fb) = (np.array(h, float) for h in heights), (np.array(f, float) for f in values)
    stalled = np.zeros(len(x), bool)
    for _ in range(MAX_BRACKET_STEPS):
        rows = np.nonzero(b - a > BRACKET_DONE)[0]
        if not len(rows):
            break
        pairs = int(np.clip((PROBES_PER_STEP // len(rows) - 1) // 2, 1, MAX_PROBE_PAIRS))
        probes = _probes(
            a[rows], x[rows], b[rows], fa[rows], fx[rows], fb[rows], stalled[rows], ends[0][rows], ends[1][rows], pairs
        )
        used = probes != x[rows, None]  # a probe at the best point is a slot left empty
        found = np.repeat(fx[rows, None], probes.shape[1], axis=1)
        found[used] = evaluate(np.broadcast_to(rows[:, None], probes.shape)[used], probes[used])
        points = np.concatenate([np.stack([a[rows], x[rows], b[rows]], axis=1), probes], axis=1)
        point_values = np.concatenate([np.stack([fa[rows], fx[rows], fb[rows]], axis=1), found], axis=1)
        width, cut = b[rows] - a[rows], stalled[rows]
        a[rows], x[rows], b[rows], fa[rows], fx[rows], fb[rows] = _narrowed(points, point_values)
        stalled[rows] = ~cut & (b[rows] - a[rows] > 0.5 * width)  # after even cuts, the parabola again
    return fx


def _probes(a, x, b, fa, fx, fb, stalled, lowest, highest, pairs):
    """2 ``pairs`` + 1 heights per bracket (k, 2 pairs + 1) in [a, b], a slot left empty where it is the best
    point x (fewer brackets, more probes each: a hull_perimeter call costs mostly its overhead).

    The best point at a piece's end: beside it (whether the end is the extreme; else the bracket is cut there).
    A bracket reaching a piece's end that is worse than its best point: twice beside that end (a section that
    loses a piece there jumps: the extreme may be the limit at the end) and the parabola's. A step that did not
    halve the bracket (or values not finite): cutting it evenly. Otherwise the vertex of the parabola through
    the three points and either side of it at half the vertex's move, 0.35 of that, ... Parabola and cuts in
    the angle t of ``_angle``: a section gaining a piece at a piece's end grows like the square root of the
    distance, smooth in t."""
    ta, tx, tb = (_angle(z, lowest, highest) for z in (a, x, b))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        p = (tx - ta) ** 2 * (fx - fb) - (tx - tb) ** 2 * (fx - fa)
        q = (tx - ta) * (fx - fb) - (tx - tb) * (fx - fa)  # <= 0 for a bracket; 0 where all three are equal
        vertex = np.where(q < 0.0, tx - 0.5 * p / np.where(q < 0.0, q, -1.0), tx)
    spread = 0.5 * np.abs(vertex - tx)
    vertex = np.clip(vertex, ta + spread, tb - spread)
    column = np.arange(2 * pairs + 1)
    offsets = np.concatenate([-(0.35 ** np.arange(pairs)), [0.0], 0.35 ** np.arange(pairs)[::-1]])
    centre = _height(vertex, lowest, highest)
    around = _height(vertex[:, None] + spread[:, None] * offsets, lowest[:, None], highest[:, None])
    around -= centre[:, None]
    around = np.sign(offsets) * np.maximum(np.abs(around), PROBE_FLOOR * np.abs(offsets) / offsets.max())
    parabolic = centre[:, None] + around
    even = (column + 1) / (len(column) + 1.0)
    cuts = _height(ta[:, None] + (tb - ta)[:, None] * even, lowest[:, None], highest[:, None])
    at_low, at_high = x <= a, x >= b
    beside = np.where(at_low, END_PROBE, -END_PROBE)[:, None] * (column == 0)
    toward_low = (a == lowest) & (fa > fx) & (x - a > 2.0 * END_PROBE)
    toward_high = (b == highest) & (fb > fx) & (b - x > 2.0 * END_PROBE) & ~toward_low
    inward = np.where(toward_low, 1.0, -1.0)[:, None]
    end = np.where(toward_low, a, b)[:, None]
    beside_end = np.where(column < 2, end + inward * END_PROBE * (column + 1), parabolic)
    finite = np.isfinite(fa) & np.isfinite(fx) & np.isfinite(fb)
    use_cuts = stalled | ~finite | (tb - ta < 4.0 * spread)
    probes = np.where(use_cuts[:, None], cuts, parabolic)
    probes = np.where((toward_low | toward_high)[:, None], beside_end, probes)
    probes = np.where((at_low | at_high)[:, None], x[:, None] + beside, probes)
    return np.clip(probes, a[:, None], b[:, None])


def _angle(z, lowest, highest):
    """The angle t in [0, pi] of height z in a piece: z = lowest + (highest - lowest) sin^2(t / 2)."""
    return 2.0 * np.arctan2(np.sqrt(np.maximum(z - lowest, 0.0)), np.sqrt(np.maximum(highest - z, 0.0)))


def _height(t, lowest, highest):
    """The height of angle t (the inverse of :func:`_angle`), each half from its nearer end."""
    width = highest - lowest
    return np.where(t < 0.5 * np.pi, lowest + width * np.sin(0.5 * t) ** 2, highest - width * np.cos(0.5 * t) ** 2)


def _narrowed(points, values):
    """The best of each row's points and its nearest neighbours either side (itself at an end): the new
    bracket (a, x, b, fa, fx, fb). Equal heights count once; of equal values the lowest height is taken."""
    order = np.argsort(points, axis=1, kind="stable")
    points, values = np.take_along_axis(points, order, axis=1), np.take_along_axis(values, order, axis=1)
    rows = np.arange(len(points))
    best = np.argmin(np.where(np.isnan(values), np.inf, values), axis=1)
    x, fx = points[rows, best], values[rows, best]
    below = np.where(points < x[:, None], np.arange(points.shape[1]), -1).max(axis=1)
    above = np.where(points > x[:, None], np.arange(points.shape[1]), points.shape[1]).min(axis=1)
    left, right = np.where(below < 0, best, below), np.where(above >= points.shape[1], best, above)
    return points[rows, left], x, points[rows, right], values[rows, left], fx, values[rows, right]


def _permuted(rotation, center, order):
    """Ellipsoids seen in axes ``order`` (a permutation of 0, 1, 2): world axis order[2] becomes 'up'."""
    p = np.eye(3)[list(order)]
    return p @ rotation, center @ p.T


def _farthest_points(rotation, center, semi_axes, points):
    """Largest distance from ``points`` (3,) or (n, 3) to each ellipsoid (n,) and the farthest points (n, 3): the
    secular equation of the farthest point, solved by bisection on its monotone branch (mu > the largest
    squared semi-axis) until the bracket stops shrinking (adjacent floats: the bits of any further step)."""
    local = np.einsum("nji,nj->ni", rotation, points - center)  # R^T (p - c)
    a2 = semi_axes**2
    low = a2.max(axis=1)
    high = low + (np.linalg.norm(local, axis=1) + semi_axes.max(axis=1)) * semi_axes.max(axis=1) * 4.0 + 1e-12
    for _ in range(100):
        mu = 0.5 * (low + high)
        value = np.sum((semi_axes * local / (a2 - mu[:, None])) ** 2, axis=1)
        outside = value > 1.0
        new_low, new_high = np.where(outside, mu, low), np.where(outside, high, mu)
        if np.array_equal(new_low, low) and np.array_equal(new_high, high):
            break
        low, high = new_low, new_high
    mu = 0.5 * (low + high)
    surface = a2 * local / (a2 - mu[:, None])
    return np.linalg.norm(surface - local, axis=1), center + np.einsum("nij,nj->ni", rotation, surface)


class MannequinLandmarks:
    """The landmarks of one mannequin (arrays of its ellipsoids), from which each extra measurement follows."""

    def __init__(self, mannequin):
        self.rotation, self.center, self.semi = mannequin.rotation, mannequin.center, mannequin.semi_axes
        topology = mannequin.topology
        self.girth = topology.girth_mask
        self.side = np.array([part.side for part in topology])
        self.arm = np.array([part.region in ("arms", "hands") for part in topology])
        bottom, height, z = section_heights(self.rotation, self.center, self.semi, mannequin.section_fractions)
        self.bottom, self.height, self.z_shoulder = float(bottom), float(height), float(z["Sh"])
        centre, k, hit = section_at_height(self.rotation, self.center, self.semi, self.at(MID_PLANE_HEIGHT))
        half = np.sqrt(k[:, 0, 0])
        self.mid_x = 0.5 * (
            np.max(np.where(hit, centre[:, 0] + half, -np.inf)) + np.min(np.where(hit, centre[:, 0] - half, np.inf))
        )

    def at(self, fraction):
        return self.bottom + fraction * self.height

    def piece_ends(self, mask):
        """Lowest and highest z of the ellipsoids ``mask``: where a section gains or loses a piece."""
        half = axis_extent(self.rotation[mask], self.semi[mask], 2)
        return np.concatenate([self.center[mask, 2] - half, self.center[mask, 2] + half])

    def girths_at(self, heights, mask):
        """Hull perimeter (m) of the sections of the ellipsoids ``mask`` at each height (array)."""
        centre, k, hit = self.sections_at(heights)
        return hull_perimeter(centre, k, hit & mask[None])

    def sections_at(self, heights):
        """The horizontal sections of every ellipsoid at each height: centre (m, n, 2), K (m, n, 2, 2), hit."""
        heights = np.asarray(heights, float)
        return section_at_height(self.rotation[None], self.center[None], self.semi[None], heights[:, None])

    def crotch(self):
        """Height (m above the soles) of the lowest point of the body on the plane x = x_c, above CROTCH_FLOOR."""
        rotation, center = _permuted(self.rotation, self.center - [self.mid_x, 0.0, 0.0], (1, 2, 0))
        centre, k, hit = section_at_height(rotation, center, self.semi, 0.0)  # (y, z) ellipses on x = x_c
        lowest = centre[:, 1] - np.sqrt(k[:, 1, 1])
        lowest = lowest[hit & (lowest > self.at(CROTCH_FLOOR))]
        return float(lowest.min() - self.bottom) if len(lowest) else np.nan

    def leg_mask(self, side):
        x = self.center[:, 0] - self.mid_x
        return self.girth & ~self.arm & ((x > 0.0) if side == "L" else (x < 0.0))

    def shoulder_point(self, side):
        centre, k, hit = section_at_height(self.rotation, self.center, self.semi, self.z_shoulder)
        sign = 1.0 if side == "L" else -1.0
        half = np.sqrt(np.maximum(k[:, 0, 0], 1e-30))
        reach = np.where(hit, sign * centre[:, 0] + half, -np.inf)
        i = int(np.argmax(reach))
        # the support point of ellipse i in direction (sign, 0): centre + sign * K e_x / sqrt(K_xx)
        return np.array([centre[i, 0] + sign * half[i], centre[i, 1] + sign * k[i, 0, 1] / half[i], self.z_shoulder])

    def arm_mask(self, side):
        return self.arm & (self.side == side)

    def arm_axis(self, side):
        """(shoulder point, unit axis, length m): from the shoulder point to the arm's farthest point."""
        return self.arm_axes((side,))[0]

    def arm_axes(self, sides=SIDES):
        """arm_axis of each side, the arms' farthest points found together (each row's bits as alone)."""
        starts = [self.shoulder_point(side) for side in sides]
        rows = [np.nonzero(self.arm_mask(side))[0] for side in sides]
        every = np.concatenate(rows)
        points = np.concatenate([np.broadcast_to(start, (len(r), 3)) for start, r in zip(starts, rows)])
        reach, farthest = _farthest_points(self.rotation[every], self.center[every], self.semi[every], points)
        axes, first = [], 0
        for start, r in zip(starts, rows):
            i = first + int(np.argmax(reach[first : first + len(r)]))
            axes.append((start, (farthest[i] - start) / reach[i], float(reach[i])))
            first += len(r)
        return axes

    def across_arm(self, side, start, axis):
        """The sections of the arm ``side``'s ellipsoids across ``axis`` (unit, from ``start``), as functions of
        the distance along it: (rotation, center) of every ellipsoid in a frame whose 'up' is the axis."""
        helper = np.array([0.0, 0.0, 1.0]) if abs(axis[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        first = np.cross(helper, axis)
        first /= np.linalg.norm(first)
        frame = np.stack([first, np.cross(axis, first), axis])
        return frame @ self.rotation, (self.center - start) @ frame.T


class _GirthFamilies:
    """Girths as functions of one parameter each, evaluated together in one hull_perimeter call: horizontal
    sections of the ellipsoids ``masks[f]`` at a height (infinity where ``nonzero[f]`` and the section is empty),
    then sections across each arm (``arms``: (frame rotation, center, mask)) at a distance along its axis."""

    def __init__(self, marks, masks, nonzero, arms):
        self.marks, self.masks, self.nonzero, self.arms = marks, np.asarray(masks), np.asarray(nonzero), arms

    def __call__(self, family, parameter):
        family, parameter = np.asarray(family, int), np.asarray(parameter, float)
        horizontal = len(self.masks)
        centre, k, hit = self.marks.sections_at(parameter)
        active = hit & self.masks[np.minimum(family, horizontal - 1)]
        for index, (rotation, center, mask) in enumerate(self.arms):
            rows = np.nonzero(family == horizontal + index)[0]
            if len(rows):
                centre[rows], k[rows], arm_hit = section_at_height(
                    rotation[None], center[None], self.marks.semi[None], parameter[rows, None]
                )
                active[rows] = arm_hit & mask
        girths = _chunked_hull_perimeter(centre, k, active)
        empty_is_none = np.where(family < horizontal, self.nonzero[np.minimum(family, horizontal - 1)], False)
        return np.where(empty_is_none & (girths <= 0.0), np.inf, girths)


def _chunked_hull_perimeter(centre, k, active):
    """hull_perimeter of many sections, in calls of at most GIRTH_CHUNK sections of similar ellipse counts (a call
    pads its sections to its largest count, or from 64 sections on makes one call per count: slower here)."""
    order = np.argsort(active.sum(axis=1), kind="stable")
    out = np.empty(len(active))
    for start in range(0, len(order), GIRTH_CHUNK):
        rows = order[start : start + GIRTH_CHUNK]
        out[rows] = hull_perimeter(centre[rows], k[rows], active[rows])
    return out


def split_measurements(values):
    """(the five {key: cm}, the extra ones {key: cm}) of measurements ``values`` holding at least the five (what a
    body mesh measured, for synthesis)."""
    return (
        {key: values[key] for key in MEASUREMENTS},
        {key: value for key, value in values.items() if key not in MEASUREMENTS},
    )


def mannequin_extra_measurements(mannequin):
    """The extra measurements of a mannequin (cm), {key: value} in EXTRA_MEASUREMENTS order; NaN where the
    mannequin has no such landmark (no arm parts, no crotch). Every girth in one band search: the calves' and
    the neck's bands refined together, the thighs' and upper arms' sections measured with their grids."""
    marks = MannequinLandmarks(mannequin)
    crotch = marks.crotch()
    legs = [marks.leg_mask(side) for side in SIDES]
    neck_mask = np.ones(len(marks.girth), bool)  # the whole section: no arm reaches the neck's band apart
    has_arms = all(marks.arm_mask(side).any() for side in SIDES)
    axes = marks.arm_axes() if has_arms else []
    arms = [(*marks.across_arm(side, start, axis), marks.arm_mask(side)) for side, (start, axis, _) in zip(SIDES, axes)]
    families = _GirthFamilies(marks, legs + [neck_mask], [False] * len(legs) + [True], arms)  # then the arms
    neck_family, first_arm = len(legs), len(legs) + 1
    neck = (neck_family, *(marks.at(f) for f in NECK_BAND), False, marks.piece_ends(neck_mask))
    bands = [neck]
    points = [(first_arm + i, UPPER_ARM_FRACTION * length) for i, (_, _, length) in enumerate(axes)]
    if np.isfinite(crotch):
        low, high = (marks.bottom + f * crotch for f in CALF_BAND)
        bands += [(i, low, high, True, marks.piece_ends(mask)) for i, mask in enumerate(legs)]
        points += [(i, marks.bottom + crotch - THIGH_DROP * marks.height) for i in range(len(legs))]
    extremes, at_points = extremes_over_bands(families, bands, points)
    out = {"crotch_height": crotch, "neck": extremes[0] if np.isfinite(extremes[0]) else np.nan}  # none: no neck
    out["arm_length"] = float(np.mean([length for _, _, length in axes])) if has_arms else np.nan
    out["upper_arm"] = float(np.mean(at_points[: len(axes)])) if has_arms else np.nan
    out["calf"] = float(np.mean(extremes[1:])) if np.isfinite(crotch) else np.nan
    out["thigh"] = float(np.mean(at_points[len(axes) :])) if np.isfinite(crotch) else np.nan
    return {key: out[key] * CM_PER_M for key in EXTRA_MEASUREMENTS}
