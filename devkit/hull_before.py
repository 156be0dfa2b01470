"""The convex-hull perimeter of section ellipses as ``core.measure.hull_perimeter`` computed it before it was
made faster (flat arrays of every sample, sorted; every piece's outermost ellipse and nodes evaluated): tests
check the two agree, the bench measures both in one run."""

import numpy as np

from ellimann_addon.core.measure import (
    QUADRATURE_CELLS,
    _compact,
    _next_in_section,
    _support_2d,
    _support_2d_with_derivative,
)

DETECTION_SAMPLES = 128  # its grid: every cell where the outermost ellipse may change sampled 16 times finer
REFINE_FACTOR = 16


NEWTON_STEPS = 3
_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(12)


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


def _max_curvature_radius(k):
    """Largest radius of curvature of each ellipse: a^2 / b with a >= b its semi-axes."""
    tr = k[..., 0, 0] + k[..., 1, 1]
    det = k[..., 0, 0] * k[..., 1, 1] - k[..., 0, 1] ** 2
    disc = np.sqrt(np.clip(0.25 * tr * tr - det, 0.0, None))
    big, small = 0.5 * tr + disc, np.clip(0.5 * tr - disc, 1e-30, None)
    return big / np.sqrt(small)


def _winners(centre, k, active, sec, theta):
    h = _support_2d(centre[sec], k[sec], theta[:, None])
    return np.argmax(np.where(active[sec], h, -np.inf), axis=1)


def hull_perimeter_before(centre, k, active):
    """(S,) perimeters of the convex hulls of the active ellipses of every section (as ``hull_perimeter``)."""
    centre, k, active = _compact(np.asarray(centre, float), np.asarray(k, float), np.asarray(active, bool))
    sections = centre.shape[0]
    if sections == 0:
        return np.zeros(0)
    step = 2.0 * np.pi / DETECTION_SAMPLES
    grid = np.arange(DETECTION_SAMPLES) * step
    h = _support_2d(centre[:, :, None, :], k[:, :, None, :, :], grid)
    h = np.where(active[:, :, None], h, -np.inf)
    winner = np.argmax(h, axis=1)
    gap = np.take_along_axis(h, winner[:, None, :], axis=1) - np.where(active[:, :, None], h, 0.0)
    gap_next = np.roll(gap, -1, axis=2)
    reach = (_max_curvature_radius(k)[:, :, None] + np.maximum(gap, gap_next)) * (step * step / 8.0)
    suspect = active[:, :, None] & (np.minimum(gap, gap_next) > 0.0) & (np.minimum(gap, gap_next) <= reach)
    sec_r, cell_r = np.nonzero(suspect.any(axis=1) | (winner != np.roll(winner, -1, axis=1)))
    sub = np.arange(1, REFINE_FACTOR) / REFINE_FACTOR
    theta_r = ((cell_r[:, None] + sub) * step).ravel()
    sec_r = np.repeat(sec_r, REFINE_FACTOR - 1)
    det_sec = np.concatenate([np.repeat(np.arange(sections), DETECTION_SAMPLES), sec_r])
    det_theta = np.concatenate([np.tile(grid, sections), theta_r])
    det_winner = np.concatenate([winner.ravel(), _winners(centre, k, active, sec_r, theta_r)])
    order = np.lexsort((det_theta, det_sec))
    det_sec, det_theta, det_winner = det_sec[order], det_theta[order], det_winner[order]
    nxt_theta, nxt_winner = _next_in_section(det_sec, det_theta, det_winner)
    change = np.nonzero(det_winner != nxt_winner)[0]
    sec = det_sec[change]
    lo, hi = det_theta[change], nxt_theta[change]
    pair = np.stack([det_winner[change], nxt_winner[change]])
    theta = _kinks(centre[sec, pair], k[sec, pair], lo, hi)
    cells = np.arange(QUADRATURE_CELLS) * (2.0 * np.pi / QUADRATURE_CELLS)
    cut_theta = np.concatenate([np.tile(cells, sections), np.mod(theta, 2.0 * np.pi)])
    cut_sec = np.concatenate([np.repeat(np.arange(sections), QUADRATURE_CELLS), sec])
    order = np.lexsort((cut_theta, cut_sec))
    cut_theta, cut_sec = cut_theta[order], cut_sec[order]
    end, _ = _next_in_section(cut_sec, cut_theta, cut_theta)
    half = 0.5 * (end - cut_theta)
    piece_winner = _winners(centre, k, active, cut_sec, cut_theta + half)
    nodes = (cut_theta + half)[:, None] + half[:, None] * _GL_NODES
    cw = centre[cut_sec, piece_winner][:, None, :]
    kw = k[cut_sec, piece_winner][:, None, :, :]
    piece = half * (_support_2d(cw, kw, nodes) @ _GL_WEIGHTS)
    piece = np.where(active[cut_sec, piece_winner], piece, 0.0)
    return np.bincount(cut_sec, weights=piece, minlength=sections)
