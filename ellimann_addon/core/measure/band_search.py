"""The extreme of a function of one parameter over a band (a height, an offset along an axis): the band cut at its
breaks and sampled on a grid, then refined by golden section (a function with kinks anywhere: a mesh's girths) or,
many bands at once, by parabolic steps (smooth between its breaks: a mannequin's girths; docs/measurements.md)."""

import numpy as np

BAND_SAMPLES = 48  # grid over a band before the extreme is refined
GOLDEN_STEPS = 40  # golden-section steps: the band's grid cell shrinks below a micrometre
BRACKET_DONE = 3e-9  # m: a smooth band search's bracket this narrow is done (a girth within nanometres)
PROBE_FLOOR = 1e-9  # m: the closest spacing of a smooth search's parabolic probes
END_PROBE = 1e-10  # m: how far beside a piece's end a smooth search looks (the limit there)
PROBES_PER_STEP = 24  # a smooth search's probes per call, shared among the brackets still open
MAX_PROBE_PAIRS = 3
MAX_BRACKET_STEPS = 60  # a smooth search's bound (halving from a cell: some 25 steps at worst)


def _band_grid(low, high, breaks, samples):
    """The band [low, high] cut at ``breaks`` and each piece sampled on a grid: (pieces, per piece). A piece's grid
    runs from END_PROBE inside its first end to END_PROBE inside its last: the function is never sampled on a
    break, where a section gains or loses a piece (an ellipse shrunk to a point) and which side of the break a
    height falls on is decided by the last bits of how the break and the section were computed (a neck's girth
    jumped by 4 mm so between two BLAS kernels); beside it, the section is the piece's own limit either way."""
    cuts = np.unique(np.clip(np.concatenate([[low, high], np.asarray(breaks, float)]), low, high))
    per_piece = max(4, samples // max(len(cuts) - 1, 1))
    start, stop = cuts[:-1], cuts[1:]
    inset = np.where(stop - start > 4.0 * END_PROBE, END_PROBE, 0.25 * (stop - start))
    t = np.linspace(0.0, 1.0, per_piece)
    return (start + inset)[:, None] + ((stop - inset) - (start + inset))[:, None] * t


def _local_cells(grid, values):
    """Every local minimum of each piece's samples (no larger than either neighbour, finite) and the samples either
    side, clipped at the piece's ends: (piece row of each, (a, x, b) heights, (fa, fx, fb) values). Every one is
    refined, not only the best: which of two dips of near-equal depth the grid deems deeper is decided by its last
    bits, and the two may differ by millimetres once refined."""
    padded = np.pad(values, ((0, 0), (1, 1)), constant_values=np.inf)
    rows, index = np.nonzero((values <= padded[:, :-2]) & (values <= padded[:, 2:]) & np.isfinite(values))
    around = [np.maximum(index - 1, 0), index, np.minimum(index + 1, grid.shape[1] - 1)]
    return rows, [grid[rows, i] for i in around], [values[rows, i] for i in around]


def extreme_over_band(function, low, high, largest, breaks=(), samples=BAND_SAMPLES, where=False, steps=GOLDEN_STEPS):
    """Largest (or smallest) value of a 1-D ``function`` (vectorised over an array of heights) on [low, high].

    The band is cut at ``breaks`` (where the function may have a kink or a narrow dip: the ends of the pieces
    a mannequin's section meets) and each piece sampled on a grid; golden-section search then refines the grid
    cells beside every local extreme of each piece's samples (:func:`_local_cells`), all at once, and the best of
    everything is returned. For a function with kinks anywhere (a mesh's girths); a smooth one is refined faster
    by :func:`extremes_over_bands`. ``steps``: golden-section steps (each narrows the bracket of two grid cells
    0.618x)."""
    grid = _band_grid(low, high, breaks, samples)
    sign = -1.0 if largest else 1.0
    values = sign * function(grid.ravel()).reshape(grid.shape)
    _, (a, _, b), _ = _local_cells(grid, values)
    ratio = (np.sqrt(5.0) - 1.0) / 2.0
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = sign * function(c), sign * function(d)
    for _ in range(steps):
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
    Each band is gridded as :func:`extreme_over_band` grids it and the cells beside every local extreme of each
    piece's samples refined by steps of a few probes per bracket in one call (:func:`_probes`: a piece's end
    checked, the parabola's vertex, even cuts where a step did not halve the bracket) until it is BRACKET_DONE
    wide. Between breaks a girth is smooth but for kinks, so a bracket closes in a handful of steps instead of
    golden section's 40. Returns (the extremes [float], the values at ``points`` (p,))."""
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
    heights, fvalues, band_of, ends, start = [[], [], []], [[], [], []], [], [[], []], 0
    for i, grid in enumerate(grids):
        rows, around, found = _local_cells(grid, grid_values[start : start + grid.size].reshape(grid.shape))
        start += grid.size
        for j in range(3):
            heights[j].append(around[j])
            fvalues[j].append(found[j])
        band_of.append(np.full(len(rows), i))
        ends[0].append(grid[rows, 0])
        ends[1].append(grid[rows, -1])
    heights, fvalues, ends = ([np.concatenate(x) for x in group] for group in (heights, fvalues, ends))
    band_of = np.concatenate(band_of).astype(int)
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
