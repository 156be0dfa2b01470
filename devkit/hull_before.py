"""The convex-hull perimeter of section ellipses as ``core.measure.tailor.hull_perimeter`` computed it before issue 14's
speed-up (main at b43ba1d, verbatim but for the name): a 128-direction grid, every cell where the outermost
ellipse changes or a hidden one seemed possible sampled 16 times finer, 12 Gauss-Legendre nodes per piece. Its
bound on a hidden ellipse used that ellipse's curvature, not the outermost one's, so it can miss a small ellipse
rising through a flat side between grid directions (tests/core/measure/test_tailor.py). Tests check the two agree on
random bodies; the bench measures both in one run."""

import numpy as np

DETECTION_SAMPLES = 128  # grid used to find which ellipse is outermost in each direction
QUADRATURE_CELLS = 32  # fixed cuts so that every smooth piece spans at most 2pi/32
GAUSS_ORDER = 12
NEWTON_STEPS = 3
REFINE_FACTOR = 16  # sub-samples in a grid cell where a hidden outermost ellipse is possible
_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(GAUSS_ORDER)
_GROUP_MIN_SECTIONS = 64  # from this many sections, those with fewer ellipses are measured apart (less padding)
_CHUNK = 256  # mannequins per batch chunk (bounds the temporary arrays to tens of MB)


def _quadratic_form(k, c, s):
    """n^T k n for the directions n = (cos, sin) = (c, s)."""
    return k[..., 0, 0] * c * c + 2.0 * k[..., 0, 1] * c * s + k[..., 1, 1] * s * s


def _support_2d(centre, k, theta):
    """Support function of section ellipses: centre (..., 2), k (..., 2, 2), theta broadcastable."""
    c, s = np.cos(theta), np.sin(theta)
    return centre[..., 0] * c + centre[..., 1] * s + np.sqrt(np.maximum(_quadratic_form(k, c, s), 0.0))


def _support_2d_with_derivative(centre, k, theta):
    """(h, dh/dtheta) of section ellipses, sharing the trigonometry."""
    c, s = np.cos(theta), np.sin(theta)
    root = np.sqrt(np.maximum(_quadratic_form(k, c, s), 1e-30))
    dquad = (k[..., 1, 1] - k[..., 0, 0]) * c * s + k[..., 0, 1] * (c * c - s * s)
    value = centre[..., 0] * c + centre[..., 1] * s + root
    slope = centre[..., 1] * c - centre[..., 0] * s + dquad / root
    return value, slope


def _compact(centre, k, active):
    """Move each section's active ellipses to the front; drop columns no section uses."""
    count = active.sum(axis=-1)
    width = max(int(count.max(initial=0)), 1)
    order = np.argsort(~active, axis=-1, kind="stable")[:, :width]
    rows = np.arange(active.shape[0])[:, None]
    return centre[rows, order], k[rows, order], active[rows, order]


def _max_curvature_radius(k):
    """Largest radius of curvature of each ellipse: a^2 / b with a >= b its semi-axes."""
    tr = k[..., 0, 0] + k[..., 1, 1]
    det = k[..., 0, 0] * k[..., 1, 1] - k[..., 0, 1] ** 2
    disc = np.sqrt(np.clip(0.25 * tr * tr - det, 0.0, None))
    big, small = 0.5 * tr + disc, np.clip(0.5 * tr - disc, 1e-30, None)
    return big / np.sqrt(small)


class _Coefficients:
    """Each section ellipse's support function h = cx cos + cy sin + sqrt(a cos^2 + b cos sin + d sin^2), as
    contiguous (S, n) arrays (fast to gather by section and by ellipse)."""

    def __init__(self, centre, k):
        self.cx, self.cy = np.ascontiguousarray(centre[..., 0]), np.ascontiguousarray(centre[..., 1])
        self.a, self.d = np.ascontiguousarray(k[..., 0, 0]), np.ascontiguousarray(k[..., 1, 1])
        self.b = 2.0 * k[..., 0, 1]

    def support(self, index, c, s, cc=None, cs=None, ss=None):
        """h of the ellipses ``index`` (a tuple of index arrays) in the directions (cos, sin) = (c, s), arrays
        broadcastable against them; cc, cs, ss: c*c, c*s, s*s when a table has them. Elementwise only, so a
        direction's value does not depend on what else is evaluated with it."""
        h = self.a[index] * (c * c if cc is None else cc)
        h += self.b[index] * (c * s if cs is None else cs)
        h += self.d[index] * (s * s if ss is None else ss)
        np.maximum(h, 0.0, out=h)
        np.sqrt(h, out=h)
        h += self.cx[index] * c
        h += self.cy[index] * s
        return h


def _winners(coefficients, active, sec, theta):
    """Index of the outermost active ellipse of section ``sec`` in direction ``theta`` (flat arrays)."""
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    h = coefficients.support((sec,), c, s)
    return np.argmax(np.where(active[sec], h, -np.inf), axis=1)


_GRID_STEP = 2.0 * np.pi / DETECTION_SAMPLES
_GRID = np.arange(DETECTION_SAMPLES) * _GRID_STEP
_FINE = np.arange(REFINE_FACTOR + 1) / REFINE_FACTOR  # a refined cell's samples, in cells from its start


def _directions(theta):
    """cos, sin and their products c*c, c*s, s*s of the angles ``theta`` (a table for :meth:`_Coefficients.support`)."""
    c, s = np.cos(theta), np.sin(theta)
    return c, s, c * c, c * s, s * s


_GRID_DIRECTIONS = _directions(_GRID)
_FINE_DIRECTIONS = _directions((np.arange(DETECTION_SAMPLES)[:, None] + _FINE[1:-1]) * _GRID_STEP)  # (N, F - 1)


def hull_perimeter_before(centre, k, active):
    """Perimeter of the convex hull of several ellipses per section.

    centre (S, n, 2), k (S, n, 2, 2) section ellipses {u: (u-c)^T k^-1 (u-c) <= 1}, active (S, n)
    bool. Returns (S,) perimeters; a section with no active ellipse has perimeter 0.
    """
    centre, k, active = np.asarray(centre, float), np.asarray(k, float), np.asarray(active, bool)
    count = active.sum(axis=-1)
    if len(count) >= _GROUP_MIN_SECTIONS and count.min() != count.max():
        # Sections are independent: measured in groups of equal ellipse counts, none is padded with others'.
        out = np.zeros(len(count))
        for size in np.unique(count):
            rows = np.nonzero(count == size)[0]
            out[rows] = hull_perimeter_before(centre[rows], k[rows], active[rows])
        return out
    centre, k, active = _compact(centre, k, active)
    sections = centre.shape[0]
    if sections == 0:
        return np.zeros(0)
    coefficients = _Coefficients(centre, k)

    # 1. Which ellipse is outermost in each grid direction.
    step = _GRID_STEP
    h = coefficients.support((Ellipsis, None), *_GRID_DIRECTIONS)  # (S, n, N)
    np.copyto(h, -np.inf, where=~active[:, :, None])
    winner = np.argmax(h, axis=1)  # (S, N)

    # 2. An ellipse that is outermost only between two grid directions would be missed. Where the
    #    winner is the same at both ends of a cell, (h_j - h_max)'' <= rho_j + gap (rho_j its
    #    largest radius of curvature), so it can only surface if its gap to the maximum is below
    #    that bound times step^2 / 8. Where the winner changes, h_max has a kink and no such bound
    #    holds. Sample both kinds of cell finely.
    with np.errstate(invalid="ignore"):  # inactive ellipses' gaps are inf (or nan without any active one)
        gap = h.max(axis=1)[:, None, :] - h
        gap_next = np.concatenate([gap[..., 1:], gap[..., :1]], axis=2)
        low = np.minimum(gap, gap_next)
        reach = np.maximum(gap, gap_next, out=gap_next)
        reach += _max_curvature_radius(k)[:, :, None]
        reach *= step * step / 8.0
        suspect = (low > 0.0) & (low <= reach) & active[:, :, None]
    changes = winner != np.concatenate([winner[:, 1:], winner[:, :1]], axis=1)
    sec_r, cell_r = np.nonzero(suspect.any(axis=1) | changes)

    # 3. Kinks: where the winner changes between consecutive directions, solve h_i = h_j. Every cell
    #    where it changes is sampled, so the kinks are in those cells, between two of their samples:
    #    the cell's start, REFINE_FACTOR - 1 points inside, the next cell's start.
    theta_r = (cell_r[:, None] + _FINE) * step  # (R, REFINE_FACTOR + 1)
    section = (sec_r[:, None, None], np.arange(centre.shape[1]))  # (R, 1, n)
    h_r = coefficients.support(section, *(t[cell_r, :, None] for t in _FINE_DIRECTIONS))  # (R, F - 1, n)
    np.copyto(h_r, -np.inf, where=~active[sec_r, None, :])
    inside = np.argmax(h_r, axis=2)
    winner_r = np.concatenate(
        [winner[sec_r, cell_r, None], inside, winner[sec_r, (cell_r + 1) % DETECTION_SAMPLES, None]], axis=1
    )
    row, at = np.nonzero(winner_r[:, :-1] != winner_r[:, 1:])
    sec = sec_r[row]
    lo, hi = theta_r[row, at], theta_r[row, at + 1]
    pair = np.stack([winner_r[row, at], winner_r[row, at + 1]])  # (2, K): outermost before, after
    theta = _kinks(centre[sec, pair], k[sec, pair], lo, hi)

    # 4. Cut the circle at the kinks and at fixed cells; integrate each piece's outermost ellipse.
    #    A piece between two fixed cuts (no kink inside) is a whole cell: its outermost ellipse is the
    #    grid's in the middle of the cell, and every section's cells are integrated at once from a table
    #    of the nodes' directions (the integrals of cells that a kink splits are not used).
    cut_theta, cut_sec, cell = _cuts(sections, np.mod(theta, 2.0 * np.pi), sec)
    end, next_cell = _next_in_section(cut_sec, cut_theta, cell)
    half = 0.5 * (end - cut_theta)
    whole = (cell >= 0) & (next_cell >= 0)
    split = ~whole
    cell_winner = winner[:, _GRID_PER_CELL // 2 :: _GRID_PER_CELL]  # (S, cells)
    cells = (np.arange(sections)[:, None, None], cell_winner[:, :, None])
    cell_integral = _weighted_sum(coefficients.support(cells, *_CELL_NODE_DIRECTIONS), _GL_WEIGHTS)  # (S, cells)
    piece_winner = np.empty(len(cut_sec), dtype=np.int64)
    piece_winner[whole] = cell_winner[cut_sec[whole], cell[whole]]
    piece_winner[split] = _winners(coefficients, active, cut_sec[split], cut_theta[split] + half[split])
    nodes = (cut_theta[split] + half[split])[:, None] + half[split, None] * _GL_NODES
    integral = np.empty(len(cut_sec))
    integral[whole] = cell_integral[cut_sec[whole], cell[whole]]
    integral[split] = _weighted_sum(
        coefficients.support((cut_sec[split, None], piece_winner[split, None]), np.cos(nodes), np.sin(nodes)),
        _GL_WEIGHTS,
    )
    piece = np.where(active[cut_sec, piece_winner], half * integral, 0.0)
    return np.bincount(cut_sec, weights=piece, minlength=sections)


def _kinks(cp, kp, lo, hi):
    """The angles in [lo, hi] where the outermost ellipse changes from cp[0], kp[0] to cp[1], kp[1] (2, K, ...):
    h_0 = h_1 by a secant start and NEWTON_STEPS Newton steps."""
    g_lo, g_hi = np.subtract(*_support_2d(cp, kp, lo)), np.subtract(*_support_2d(cp, kp, hi))
    denom = g_lo - g_hi
    frac = np.divide(g_lo, denom, out=np.full_like(g_lo, 0.5), where=np.abs(denom) > 0.0)
    theta = lo + (hi - lo) * np.clip(frac, 0.0, 1.0)
    for _ in range(NEWTON_STEPS):
        value, slope = _support_2d_with_derivative(cp, kp, theta)
        g, dg = value[0] - value[1], slope[0] - slope[1]
        update = np.divide(g, dg, out=np.zeros_like(g), where=np.abs(dg) > 1e-300)
        theta = np.minimum(np.maximum(theta - update, lo), hi)
    return theta


_CELLS = np.arange(QUADRATURE_CELLS) * (2.0 * np.pi / QUADRATURE_CELLS)
_GRID_PER_CELL = DETECTION_SAMPLES // QUADRATURE_CELLS


def _cell_nodes():
    """The Gauss-Legendre nodes of every whole cell (QUADRATURE_CELLS, GAUSS_ORDER), computed as
    :func:`hull_perimeter` computes a piece's."""
    end = np.append(_CELLS[1:], _CELLS[0] + 2.0 * np.pi)
    half = 0.5 * (end - _CELLS)
    return (_CELLS + half)[:, None] + half[:, None] * _GL_NODES


_CELL_NODE_DIRECTIONS = _directions(_cell_nodes())


def _cuts(sections, theta, sec):
    """The fixed cells of every section and the kinks (theta, sec), sorted by (section, angle), a cell before
    a kink at the same angle: (theta, sec, cell index or -1 for a kink) of every cut. Only the kinks are
    sorted; the cells are merged in."""
    order = np.lexsort((theta, sec))
    theta, sec = theta[order], sec[order]
    # A kink goes after the cells of the sections before it, the cells of its own section up to its angle
    # and the kinks sorted before it.
    kink_at = sec * QUADRATURE_CELLS + np.searchsorted(_CELLS, theta, side="right") + np.arange(len(theta))
    total = sections * QUADRATURE_CELLS + len(theta)
    is_cell = np.ones(total, dtype=bool)
    is_cell[kink_at] = False
    cut_theta, cut_sec, cell = np.empty(total), np.empty(total, dtype=np.int64), np.full(total, -1)
    cut_theta[kink_at], cut_sec[kink_at] = theta, sec
    cut_theta[is_cell], cut_sec[is_cell] = np.tile(_CELLS, sections), np.repeat(np.arange(sections), QUADRATURE_CELLS)
    cell[is_cell] = np.tile(np.arange(QUADRATURE_CELLS), sections)
    return cut_theta, cut_sec, cell


def _weighted_sum(values, weights):
    """values (..., q) @ weights (q,), summed in a fixed order: the same bits for a row whatever the batch (a
    matrix product's summation order depends on the array's size and alignment)."""
    total = values[..., 0] * weights[0]
    for j in range(1, len(weights)):
        total += values[..., j] * weights[j]
    return total


def _next_in_section(sec, theta, value):
    """For rows sorted by (sec, theta): the next row's theta and value, wrapping around the circle."""
    nxt = np.arange(1, len(sec) + 1)
    last = np.ones(len(sec), dtype=bool)
    last[:-1] = sec[1:] != sec[:-1]
    nxt[last] = np.searchsorted(sec, sec[last])
    nxt_theta = theta[nxt] + np.where(last, 2.0 * np.pi, 0.0)
    return nxt_theta, value[nxt]
