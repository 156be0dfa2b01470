"""The perimeter of the convex hull of ellipses in a plane, per section, batched: Cauchy's formula
P = integral_0^2pi max_i h_i(theta) dtheta, h_i the ellipses' support functions, exact up to floating point.

The angles where the maximising ellipse changes (the kinks of max_i h_i) are found from a grid of directions:
a cell is cleared of an ellipse hidden between its ends by a bound on how far one can rise above the
outermost (:func:`_may_surface`); where the outermost changes, the kink is solved by Newton (:func:`_kinks`);
whatever the bound cannot clear is sampled finer (:func:`_scan`). Each smooth piece, one ellipse's support between
two kinks, is integrated in closed form: the linear part directly, the root by the elliptic integral of the second
kind (:func:`_integrate`, Carlson's duplication). A section symmetric about x = 0 is integrated over its right half
(:func:`_right_half`); one measured a moment ago can follow its kinks instead of searching (``warm``). m_T
(``core.measure.tailor``) measures its girths with it.
"""

from dataclasses import dataclass

import numpy as np

from .ellipse_support import compact_sections, curvature_radii, support_2d_with_derivative
from .elliptic import elliptic_e

CELLS = 32  # grid directions over the circle, which find the outermost ellipses
NEWTON_STEPS = 8  # from a secant start across a whole grid cell ...
NEWTON_DONE = 1e-13  # ... until a kink moves less than this (radians)
KINK_TOLERANCE = 1e-10  # |h_0 - h_1| at a kink found, relative to the ellipses' size (else: sampled finer)
REFINE_FACTOR = 8  # a grid cell in doubt is sampled this many times finer, ...
REFINE_LEVELS = 3  # ... at most this many times
_GROUP_MIN_SECTIONS = 64  # from this many sections, those with fewer ellipses are measured apart (less padding)
_PAIRED_WIDTH = 12  # wider sections are compacted before their columns are compared pairwise


class _Coefficients:
    """Each section ellipse's support function h = cx cos + cy sin + sqrt(a cos^2 + b cos sin + d sin^2), as
    contiguous (S, n) arrays (fast to gather by section and by ellipse)."""

    def __init__(self, centre, k):
        self.cx, self.cy = np.ascontiguousarray(centre[..., 0]), np.ascontiguousarray(centre[..., 1])
        self.a, self.d = np.ascontiguousarray(k[..., 0, 0]), np.ascontiguousarray(k[..., 1, 1])
        self.b = 2.0 * k[..., 0, 1]

    def root(self, index, c, s, cc=None, cs=None, ss=None):
        """sqrt(n^T k n) of the ellipses ``index`` (a tuple of index arrays) in the directions (cos, sin) = (c, s),
        arrays broadcastable against them; cc, cs, ss: c*c, c*s, s*s when a table has them. Elementwise only, so
        a direction's value does not depend on what else is evaluated with it."""
        h = self.a[index] * (c * c if cc is None else cc)
        h += self.b[index] * (c * s if cs is None else cs)
        h += self.d[index] * (s * s if ss is None else ss)
        np.maximum(h, 0.0, out=h)
        return np.sqrt(h, out=h)

    def support(self, index, c, s, cc=None, cs=None, ss=None):
        """h of the ellipses ``index`` in the directions (c, s) (as :meth:`root`)."""
        h = self.root(index, c, s, cc, cs, ss)
        h += self.cx[index] * c
        h += self.cy[index] * s
        return h

    def centre_integral(self, index, c0, s0, c1, s1):
        """The integral of cx cos + cy sin from the angle (c0, s0) to (c1, s1): the support's linear part."""
        return self.cx[index] * (s1 - s0) - self.cy[index] * (c1 - c0)


def _directions(theta):
    """cos, sin and their products c*c, c*s, s*s of the angles ``theta`` (a table for :meth:`_Coefficients.support`)."""
    c, s = np.cos(theta), np.sin(theta)
    return c, s, c * c, c * s, s * s


class _Arc:
    """The directions a group of sections is integrated over, cut into the equal cells of the grid that finds the
    outermost ellipses: the whole circle, or, for a section symmetric about x = 0, the right half [-pi/2, pi/2]
    counted twice (its support H has H(pi - theta) = H(theta)), with the poles' directions exact."""

    def __init__(self, start, cells, copies):
        self.cells, self.copies = cells, copies
        span = 2.0 * np.pi / copies
        self.step = span / cells
        grid = start + np.arange(cells + 1) * self.step
        grid[-1] = start + span
        self.end = grid[-1]
        c, s = np.cos(grid), np.sin(grid)
        if copies == 2:
            c[[0, -1]], s[[0, -1]] = 0.0, (-1.0, 1.0)
        self.directions = (c, s, c * c, c * s, s * s)  # at the cells' ends, (cells + 1,) each
        self.cell_start = grid[:-1]
        self.cell_width = grid[1:] - grid[:-1]


_FULL = _Arc(0.0, CELLS, 1)
_RIGHT_HALF = _Arc(-0.5 * np.pi, CELLS // 2, 2)


def _may_surface(gap_start, gap_end, bend, length):
    """Whether an ellipse j below the outermost one w at both ends of an interval of ``length`` (gaps
    g = h_w - h_j >= 0 there) can rise above it inside. With h'' + h = rho (the radius of curvature),
    f = h_j - h_w has f'' = rho_j - rho_w - f >= -bend - max(f, 0), ``bend`` = max rho_w - min rho_j (_bend): f
    stays below its chord plus (bend + max f) v (L - v) / 2 (v from the start), so it can only turn positive where
    that parabola with bend alone does, i.e. its vertex v* = L/2 + (g_start - g_end) / (bend L) is inside and
    bend v*^2 / 2 > g_start. w itself (gaps 0) and inactive ellipses (gaps inf) never surface."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):  # inf gaps, zero bends
        vertex = 0.5 * length + (gap_start - gap_end) / (bend * length)
        return (
            (vertex > 0.0)
            & (vertex < length)
            & (0.5 * bend * vertex * vertex > gap_start)
            & (np.maximum(gap_start, gap_end) > 0.0)
            & np.isfinite(gap_start)
            & np.isfinite(gap_end)
        )


@dataclass
class HullStructure:
    """Where the outermost ellipse of each section changes (the kinks of max_i h_i), in the caller's ellipse columns:
    what :func:`hull_perimeter` needs to measure the sections again after a small move without searching (``warm``)."""

    mirrored: np.ndarray  # (S,) bool: integrated over the right half (:func:`_right_half`)
    first: np.ndarray  # (S,) the ellipse outermost at the arc's start (-1 where no ellipse is active)
    kink_section: np.ndarray  # (K,) sorted by section, then angle
    kink_theta: np.ndarray  # (K,)
    kink_after: np.ndarray  # (K,) the ellipse outermost after the kink

    @staticmethod
    def empty(sections):
        """The structure of ``sections`` sections with no ellipse and no kink."""
        return HullStructure(
            np.zeros(sections, dtype=bool),
            np.full(sections, -1),
            np.zeros(0, dtype=np.int64),
            np.zeros(0),
            np.zeros(0, dtype=np.int64),
        )

    def take(self, rows):
        """The structure of the sections ``rows``, numbered from 0 in that order."""
        rows = np.asarray(rows, dtype=np.int64)
        renumber = np.full(len(self.first), -1)
        renumber[rows] = np.arange(len(rows))
        keep = renumber[self.kink_section] >= 0
        return HullStructure(
            self.mirrored[rows],
            self.first[rows],
            *_sorted_kinks(renumber[self.kink_section[keep]], self.kink_theta[keep], self.kink_after[keep]),
        )

    def replaced(self, rows, other):
        """This structure with the sections ``rows`` those of ``other`` (one for each, in that order)."""
        rows = np.asarray(rows, dtype=np.int64)
        mirrored, first = self.mirrored.copy(), self.first.copy()
        mirrored[rows], first[rows] = other.mirrored, other.first
        mine = np.ones(len(first), dtype=bool)
        mine[rows] = False
        keep = mine[self.kink_section]
        return HullStructure(
            mirrored,
            first,
            *_sorted_kinks(
                np.concatenate([self.kink_section[keep], rows[other.kink_section]]),
                np.concatenate([self.kink_theta[keep], other.kink_theta]),
                np.concatenate([self.kink_after[keep], other.kink_after]),
            ),
        )

    def renamed(self, names):
        """The same structure with every ellipse e called names[e], or names[section, e] when ``names`` is one row
        per section (-1 stays -1, and so does a name of -1)."""
        names = np.asarray(names)

        def rename(sec, e):
            if not names.size:
                return np.full_like(e, -1)
            picked = names[sec, np.maximum(e, 0)] if names.ndim == 2 else names[np.maximum(e, 0)]
            return np.where(e >= 0, picked, -1)

        return HullStructure(
            self.mirrored,
            rename(np.arange(len(self.first)), self.first),
            self.kink_section,
            self.kink_theta,
            rename(self.kink_section, self.kink_after),
        )

    @staticmethod
    def concatenate(parts):
        """One structure of the sections of ``parts``, in order."""
        if not parts:
            return HullStructure.empty(0)
        offsets = np.cumsum([0] + [len(part.first) for part in parts])
        return HullStructure(
            np.concatenate([part.mirrored for part in parts]),
            np.concatenate([part.first for part in parts]),
            np.concatenate([part.kink_section + offset for part, offset in zip(parts, offsets)]),
            np.concatenate([part.kink_theta for part in parts]),
            np.concatenate([part.kink_after for part in parts]),
        )


def hull_perimeter(centre, k, active, warm=None, structure=False):
    """Perimeter of the convex hull of several ellipses per section.

    centre (S, n, 2), k (S, n, 2, 2) section ellipses {u: (u-c)^T k^-1 (u-c) <= 1}, active (S, n)
    bool. Returns (S,) perimeters; a section with no active ellipse has perimeter 0. A section that is its own
    mirror image in x = 0, bit for bit (a synthesized mannequin's), is integrated over its right half only, without
    the left ellipses that cannot reach into it (:func:`_right_half`).

    ``structure=True`` returns (perimeters, :class:`HullStructure`). ``warm``: the structure of the same sections a
    moment ago, the ellipses having moved a little since: each kink is solved again by Newton from where it was and
    nothing is searched, so an ellipse that has risen above the others since would be missed (for the steps of a
    refinement, not for a result); a section whose kinks do not follow (one does not converge or lands on a crossing
    the wrong way round, two swap or meet, an outermost ellipse is no longer cut, the symmetry changed) is searched.
    """
    centre, k, active = np.asarray(centre, float), np.asarray(k, float), np.asarray(active, bool)
    sections = centre.shape[0]
    out, first = np.zeros(sections), np.full(sections, -1)
    if sections == 0 or centre.shape[1] == 0:
        return (out, HullStructure.empty(sections)) if structure else out
    kinks = [(np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0, dtype=np.int64))]  # section, angle, after
    given = np.broadcast_to(np.arange(centre.shape[1]), active.shape)
    if centre.shape[1] > _PAIRED_WIDTH:  # _right_half compares every pair of columns: the unused ones go first
        centre, k, active, given = compact_sections(centre, k, active)
    mirrored, used = _right_half(centre, k, active)
    centre, k, used, columns = compact_sections(centre, k, used)
    columns = np.take_along_axis(given, columns, axis=1)
    cold = np.ones(sections, dtype=bool)
    if warm is not None:
        cold, (warm_first, sec, theta, after) = _follow(centre, k, used, mirrored, _to_columns(warm, columns))
        first[~cold] = warm_first[~cold]
        kinks.append((sec[~cold[sec]], theta[~cold[sec]], after[~cold[sec]]))
    count = used.sum(axis=-1)
    # Sections are independent: searched in groups of one arc and, from _GROUP_MIN_SECTIONS on, of equal ellipse
    # counts, so that none is padded with others' ellipses.
    group = 2 * count + mirrored if sections >= _GROUP_MIN_SECTIONS else mirrored.astype(int)
    for key in np.unique(group[cold]):
        rows = np.nonzero(cold & (group == key))[0]
        width = max(int(count[rows].max()), 1)  # the sections' ellipses are in front: narrower groups drop the rest
        first[rows], theta, sec, after = _search(
            centre[rows, :width], k[rows, :width], used[rows, :width], _RIGHT_HALF if mirrored[rows[0]] else _FULL
        )
        kinks.append((rows[sec], theta, after))
    sec, theta, after = _sorted_kinks(*(np.concatenate(column) for column in zip(*kinks)))
    out = _integrate(_Coefficients(centre, k), used, mirrored, first, theta, sec, after)
    if not structure:
        return out
    return out, HullStructure(
        mirrored,
        np.where(first >= 0, columns[np.arange(sections), np.maximum(first, 0)], -1),
        sec,
        theta,
        columns[sec, after],
    )


def _sorted_kinks(sec, theta, after):
    order = np.lexsort((theta, sec))
    return sec[order], theta[order], after[order]


def _to_columns(structure, columns):
    """``structure`` (in the caller's ellipse columns) in the compacted ones, ``columns`` (S, width) the caller's
    column of each: -1 for an ellipse not among them."""
    width = (
        max(int(columns.max(initial=0)), int(structure.first.max(initial=0)), int(structure.kink_after.max(initial=0)))
        + 1
    )
    inverse = np.full((len(columns), width), -1)
    np.put_along_axis(inverse, columns, np.broadcast_to(np.arange(columns.shape[1]), columns.shape), axis=1)
    return structure.renamed(inverse)


def _follow(centre, k, used, mirrored, warm):
    """The kinks of a former structure (:func:`hull_perimeter`'s ``warm``) solved again, all in compacted columns:
    (the sections to search instead (S,), the structure followed: (first, section, angle, after))."""
    sections = len(mirrored)
    rows = np.arange(sections)
    sec, theta, after = warm.kink_section, warm.kink_theta, warm.kink_after
    opens = np.ones(len(sec), dtype=bool)
    opens[1:] = sec[1:] != sec[:-1]
    before = np.where(opens, warm.first[sec], np.roll(after, 1))
    ok = (warm.mirrored == mirrored) & (warm.first >= 0) & used[rows, np.maximum(warm.first, 0)]
    cut = (before >= 0) & (after >= 0) & used[sec, np.maximum(before, 0)] & used[sec, np.maximum(after, 0)]
    ok[sec[~cut]] = False
    lo = np.where(mirrored[sec], _RIGHT_HALF.cell_start[0], _FULL.cell_start[0])
    hi = np.where(mirrored[sec], _RIGHT_HALF.end, _FULL.end)
    coefficients = _Coefficients(centre, k)
    index = ((sec, np.maximum(before, 0)), (sec, np.maximum(after, 0)))
    theta = _newton(coefficients, index, theta.copy(), lo, hi)
    c, s = np.cos(theta), np.sin(theta)
    size = coefficients.root(index[0], c, s) + coefficients.root(index[1], c, s)
    miss = np.abs(coefficients.support(index[0], c, s) - coefficients.support(index[1], c, s)) > KINK_TOLERANCE * size
    # Supports crossing more than once: Newton may land on a crossing the wrong way round, or on another kink.
    miss |= np.subtract(*(support_2d_with_derivative(centre[i], k[i], theta)[1] for i in index)) > 0.0
    ok[sec[miss]] = False
    swapped = (sec[1:] == sec[:-1]) & (theta[1:] <= theta[:-1])
    ok[sec[1:][swapped]] = False
    return ~ok, (warm.first, sec, theta, after)


def _right_half(centre, k, active):
    """Which sections are their own mirror image in x = 0 (S,), and the ellipses their right half needs (S, n).

    An ellipse L left of the mid-plane whose mirror image R is right of it never rises above R on the right half
    when |c_x| b > |k_xy| (b the smallest semi-axis): h_L - h_R = -2 cos(theta) (c_x + 2 k_xy sin(theta) /
    (sqrt(q_L) + sqrt(q_R))), with q = n^T k n >= b^2. Any other left ellipse is kept."""
    cx, cy = centre[..., 0], centre[..., 1]
    a, b, d = k[..., 0, 0], k[..., 0, 1], k[..., 1, 1]
    pair = (
        (cx[:, :, None] == -cx[:, None, :])
        & (cy[:, :, None] == cy[:, None, :])
        & (a[:, :, None] == a[:, None, :])
        & (b[:, :, None] == -b[:, None, :])
        & (d[:, :, None] == d[:, None, :])
        & active[:, None, :]
    )
    mirrored = np.all(pair.any(axis=2) | ~active, axis=1) & active.any(axis=1)
    smallest = 0.5 * (a + d) - np.sqrt(np.maximum(0.25 * (a - d) ** 2 + b * b, 0.0))
    with np.errstate(invalid="ignore"):
        dominated = np.abs(cx) * np.sqrt(np.maximum(smallest, 0.0)) > np.abs(b)
    return mirrored, np.where(mirrored[:, None], active & ((cx >= 0.0) | ~dominated), active)


def _search(centre, k, active, arc):
    """Where max_i h_i changes ellipse over ``arc`` (an :class:`_Arc`), per section: (the ellipse outermost at the
    arc's start (-1 if none is active), and the kinks: angle, section, the ellipse outermost after it)."""
    sections = centre.shape[0]
    coefficients = _Coefficients(centre, k)
    largest, smallest = curvature_radii(k)  # (S, n)

    # 1. Which ellipse is outermost in each grid direction.
    h = coefficients.support((Ellipsis, None), *arc.directions)  # (S, n, cells + 1)
    np.copyto(h, -np.inf, where=~active[:, :, None])
    winner = np.argmax(h, axis=1)  # (S, cells + 1)

    # 2. An ellipse that is outermost only between two grid directions would be missed: cells where one may
    #    surface (_may_surface) and cells where the winner changes (h_max has a kink there) are sampled finely.
    with np.errstate(invalid="ignore"):  # inactive ellipses' gaps are inf (or nan without any active one)
        gap = h.max(axis=1)[:, None, :] - h  # (S, n, cells + 1)
    cell_winner = winner[:, :-1]  # (S, cells): at each cell's start
    bend = np.maximum(largest[np.arange(sections)[:, None], cell_winner][:, None, :] - smallest[:, :, None], 0.0)
    suspect = _may_surface(gap[..., :-1], gap[..., 1:], bend, arc.step).any(axis=1)  # (S, cells): the winner stays
    changes = cell_winner != winner[:, 1:]
    sec_r, cell_r = np.nonzero(suspect | changes)

    # 3. Kinks, where the outermost ellipse changes, in the cells sampled finely (_scan); a cell that the
    #    sampling cannot clear of a hidden ellipse is sampled again, finer.
    start, width = arc.cell_start[cell_r], arc.cell_width[cell_r]
    ends = (h[sec_r, :, cell_r], h[sec_r, :, cell_r + 1])  # (R, n) each
    kinks = []
    for level in range(REFINE_LEVELS + 1):
        theta, kink_row, after, doubtful = _scan(
            coefficients, active, (largest, smallest), sec_r, start, width, REFINE_FACTOR**level, ends
        )
        keep = ~doubtful[kink_row] if level < REFINE_LEVELS else np.ones(len(kink_row), dtype=bool)
        kinks.append((theta[keep], sec_r[kink_row[keep]], after[keep]))
        if level == REFINE_LEVELS or not doubtful.any():
            break
        sec_r, start, width = sec_r[doubtful], start[doubtful], width[doubtful]
        ends = (ends[0][doubtful], ends[1][doubtful])
    theta, sec, after = (np.concatenate(column) for column in zip(*kinks))

    first = np.where(active.any(axis=1), winner[:, 0], -1)
    return first, theta, sec, after


def _integrate(coefficients, active, mirrored, first, theta, sec, after):
    """The perimeter of each section from its outermost ellipse at its arc's start (S,) (the right half where
    ``mirrored``, else the whole circle) and its kinks (angle, section, the ellipse outermost after it): each piece
    between them is its ellipse's support integrated in closed form, the linear part and the root, sqrt(q) =
    sqrt(alpha + beta) sqrt(1 - m sin^2(theta - phi)) with alpha +- beta the squared semi-axes and
    m = 2 beta / (alpha + beta), by the elliptic integral E (:func:`elliptic.elliptic_e`)."""
    sections = len(first)
    arc_start = np.where(mirrored, _RIGHT_HALF.cell_start[0], _FULL.cell_start[0])
    # Each piece from its start (the arc's, or a kink; the arc's first where they coincide) to the next.
    sec, start, winner = _sorted_kinks(
        np.concatenate([np.arange(sections), sec]), np.concatenate([arc_start, theta]), np.concatenate([first, after])
    )
    last = np.ones(len(sec), dtype=bool)
    last[:-1] = sec[1:] != sec[:-1]
    end = np.where(last, np.where(mirrored, _RIGHT_HALF.end, _FULL.end)[sec], np.roll(start, -1))
    index = (sec, np.maximum(winner, 0))
    a, b, d = coefficients.a[index], coefficients.b[index], coefficients.d[index]
    alpha, spread, turn = 0.5 * (a + d), 0.5 * (a - d), 0.5 * b
    beta = np.sqrt(spread * spread + turn * turn)
    phase = 0.5 * np.arctan2(turn, spread)
    top = alpha + beta
    m = np.divide(2.0 * beta, top, out=np.zeros_like(top), where=top > 0.0)
    e = elliptic_e(np.stack([start - phase, end - phase]), m)
    root = np.sqrt(top) * (e[1] - e[0])
    linear = coefficients.centre_integral(index, np.cos(start), np.sin(start), np.cos(end), np.sin(end))
    piece = np.where((winner >= 0) & active[index], root + linear, 0.0)
    return np.where(mirrored, _RIGHT_HALF.copies, _FULL.copies) * np.bincount(sec, weights=piece, minlength=sections)


def _scan(coefficients, active, radii, sec, start, width, samples, ends):
    """Find the kinks in the intervals [start, start + width] (R,) of sections ``sec``, given every ellipse's h at
    both ends (``ends``: two (R, n)), from ``samples`` equal sub-intervals: in each one where the outermost
    ellipse changes, h_0 = h_1 is solved (:func:`_kinks`).

    Returns (theta (K,), row (K,) the interval of each kink, the ellipse outermost after it (K,), doubtful
    (R,)): an interval is doubtful where :func:`_may_surface` cannot rule out an ellipse rising above the
    outermost one inside a sub-interval with one outermost ellipse, or on either side of a kink (up to the kink,
    from it), or a third ellipse is above the pair at the kink, or the pair's supports differ there by more than
    KINK_TOLERANCE."""
    n = active.shape[1]
    inner = np.arange(1, samples) / samples
    theta = np.concatenate(
        [start[:, None], start[:, None] + width[:, None] * inner, (start + width)[:, None]], axis=1
    )  # (R, samples + 1)
    h = np.empty((len(sec), samples + 1, n))
    h[:, 0], h[:, -1] = ends
    h[:, 1:-1] = coefficients.support(
        (sec[:, None, None], np.arange(n)), np.cos(theta[:, 1:-1, None]), np.sin(theta[:, 1:-1, None])
    )
    np.copyto(h[:, 1:-1], -np.inf, where=~active[sec, None, :])
    winner = np.argmax(h, axis=2)  # (R, samples + 1)
    with np.errstate(invalid="ignore"):
        gap = np.take_along_axis(h, winner[..., None], axis=2) - h  # (R, samples + 1, n)
    step = width / samples
    same = winner[:, :-1] == winner[:, 1:]
    largest, smallest = radii
    bend = np.maximum(largest[sec[:, None], winner[:, :-1]][..., None] - smallest[sec, None, :], 0.0)
    hidden = _may_surface(gap[:, :-1], gap[:, 1:], bend, step[:, None, None]).any(axis=2)
    doubtful = (same & hidden).any(axis=1)

    row, at = np.nonzero(~same)
    lo, hi = theta[row, at], theta[row, at + 1]
    pair = np.stack([winner[row, at], winner[row, at + 1]])  # (2, K)
    kink_sec = sec[row]
    # h_A - h_B at the sub-interval's ends: B's gap to A at the start, minus A's gap to B at the end.
    kink = _kinks(
        coefficients,
        ((kink_sec, pair[0]), (kink_sec, pair[1])),
        lo,
        hi,
        gap[row, at, pair[1]],
        -gap[row, at + 1, pair[0]],
    )
    h_kink = coefficients.support((kink_sec[:, None], np.arange(n)), np.cos(kink)[:, None], np.sin(kink)[:, None])
    np.copyto(h_kink, -np.inf, where=~active[kink_sec])  # (K, n)
    columns = np.arange(n)
    not_before, not_after = columns != pair[0][:, None], columns != pair[1][:, None]  # (K, n)
    before = np.take_along_axis(h_kink, pair[0][:, None], axis=1)
    after = np.take_along_axis(h_kink, pair[1][:, None], axis=1)
    bend_before = np.maximum(largest[kink_sec, pair[0]][:, None] - smallest[kink_sec], 0.0)
    bend_after = np.maximum(largest[kink_sec, pair[1]][:, None] - smallest[kink_sec], 0.0)
    with np.errstate(invalid="ignore"):
        # A third ellipse above both at the kink; or any ellipse, the other of the pair too (a second crossing),
        # rising above the one outermost from the sub-interval's start to the kink, or from the kink to its end.
        doubt = (h_kink > np.maximum(before, after)) & not_before & not_after
        size = coefficients.root((kink_sec, pair[0]), np.cos(kink), np.sin(kink))
        size += coefficients.root((kink_sec, pair[1]), np.cos(kink), np.sin(kink))
        doubt[np.abs(before - after)[:, 0] > KINK_TOLERANCE * size] = True  # Newton has not converged
        doubt |= _may_surface(gap[row, at], before - h_kink, bend_before, (kink - lo)[:, None]) & not_before
        doubt |= _may_surface(after - h_kink, gap[row, at + 1], bend_after, (hi - kink)[:, None]) & not_after
    doubtful[row[doubt.any(axis=1)]] = True
    return kink, row, pair[1], doubtful


def _kinks(coefficients, index, lo, hi, g_lo, g_hi):
    """The angles in [lo, hi] where the outermost ellipse changes from the ellipse index[0] to index[1] (each a
    tuple (section, ellipse) of (K,) arrays): h_0 = h_1 by a secant start from g = h_0 - h_1 at lo and hi, then
    Newton steps (:func:`_newton`)."""
    denom = g_lo - g_hi
    frac = np.divide(g_lo, denom, out=np.full_like(g_lo, 0.5), where=np.abs(denom) > 0.0)
    theta = lo + (hi - lo) * np.clip(frac, 0.0, 1.0)
    return _newton(coefficients, index, theta, lo, hi)


def _newton(coefficients, index, theta, lo, hi):
    """h_0 = h_1 for the ellipses index[0] and index[1] (each a tuple (section, ellipse) of (K,) arrays) by Newton
    steps from ``theta`` (changed in place), kept in [lo, hi], at most NEWTON_STEPS, each kink's until its step is
    below NEWTON_DONE."""
    (a0, b0, d0), (a1, b1, d1) = ((coefficients.a[i], coefficients.b[i], coefficients.d[i]) for i in index)
    dcx = coefficients.cx[index[0]] - coefficients.cx[index[1]]
    dcy = coefficients.cy[index[0]] - coefficients.cy[index[1]]
    todo = np.arange(len(theta))
    for _ in range(NEWTON_STEPS):
        t = theta[todo]
        c, s = np.cos(t), np.sin(t)
        cc, cs, ss = c * c, c * s, s * s
        p0 = (a0[todo], b0[todo], d0[todo])
        p1 = (a1[todo], b1[todo], d1[todo])
        root0 = np.sqrt(np.maximum(p0[0] * cc + p0[1] * cs + p0[2] * ss, 1e-30))
        root1 = np.sqrt(np.maximum(p1[0] * cc + p1[1] * cs + p1[2] * ss, 1e-30))
        x, y = dcx[todo], dcy[todo]
        g = x * c + y * s + root0 - root1
        turn = cc - ss  # d(a cc + b cs + d ss)/dtheta = 2 (d - a) cs + b (cc - ss)
        dg = (
            y * c
            - x * s
            + (2.0 * (p0[2] - p0[0]) * cs + p0[1] * turn) / (2.0 * root0)
            - (2.0 * (p1[2] - p1[0]) * cs + p1[1] * turn) / (2.0 * root1)
        )
        update = np.divide(g, dg, out=np.zeros_like(g), where=np.abs(dg) > 1e-300)
        new = np.minimum(np.maximum(t - update, lo[todo]), hi[todo])
        moved = np.abs(new - t) > NEWTON_DONE
        theta[todo] = new
        todo = todo[moved]
        if not len(todo):
            break
    return theta
