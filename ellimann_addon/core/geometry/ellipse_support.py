"""Support functions of ellipses in a plane, batched: a section ellipse is its centre (..., 2) and the matrix k
(..., 2, 2) with h(theta) = c . n + sqrt(n^T k n), n = (cos theta, sin theta). The section hull (m_T's girths) is
built on them; :func:`hull_boundary` draws that hull.
"""

import numpy as np


def quadratic_form(k, c, s):
    """n^T k n for the directions n = (cos, sin) = (c, s)."""
    return k[..., 0, 0] * c * c + 2.0 * k[..., 0, 1] * c * s + k[..., 1, 1] * s * s


def support_2d(centre, k, theta):
    """Support function of section ellipses: centre (..., 2), k (..., 2, 2), theta broadcastable."""
    c, s = np.cos(theta), np.sin(theta)
    return centre[..., 0] * c + centre[..., 1] * s + np.sqrt(np.maximum(quadratic_form(k, c, s), 0.0))


def support_2d_with_derivative(centre, k, theta):
    """(h, dh/dtheta) of section ellipses, sharing the trigonometry."""
    c, s = np.cos(theta), np.sin(theta)
    root = np.sqrt(np.maximum(quadratic_form(k, c, s), 1e-30))
    dquad = (k[..., 1, 1] - k[..., 0, 0]) * c * s + k[..., 0, 1] * (c * c - s * s)
    value = centre[..., 0] * c + centre[..., 1] * s + root
    slope = centre[..., 1] * c - centre[..., 0] * s + dquad / root
    return value, slope


def compact_sections(centre, k, active):
    """Move each section's active ellipses to the front; drop columns no section uses. Returns the moved arrays and
    the column each came from (S, width)."""
    count = active.sum(axis=-1)
    width = max(int(count.max(initial=0)), 1)
    order = np.argsort(~active, axis=-1, kind="stable")[:, :width]
    rows = np.arange(active.shape[0])[:, None]
    return centre[rows, order], k[rows, order], active[rows, order], order


def curvature_radii(k):
    """Largest and smallest radius of curvature of each ellipse: a^2 / b and b^2 / a, a >= b its semi-axes."""
    tr = k[..., 0, 0] + k[..., 1, 1]
    det = k[..., 0, 0] * k[..., 1, 1] - k[..., 0, 1] ** 2
    disc = np.sqrt(np.clip(0.25 * tr * tr - det, 0.0, None))
    big, small = 0.5 * tr + disc, np.clip(0.5 * tr - disc, 1e-30, None)
    return big / np.sqrt(small), small / np.sqrt(np.maximum(big, 1e-30))


def hull_boundary(centre, k, active, samples=256):
    """Points along the convex hull of one section's ellipses (for drawing): (samples, 2).

    Each point is the support point of the outermost ellipse in that direction; consecutive
    points across a change of ellipse form the hull's straight bridges.
    """
    centre, k, active = np.asarray(centre, float), np.asarray(k, float), np.asarray(active, bool)
    if not active.any():
        return np.zeros((0, 2))
    theta = np.linspace(0.0, 2.0 * np.pi, samples, endpoint=False)
    h = np.where(active[:, None], support_2d(centre[:, None, :], k[:, None, :, :], theta), -np.inf)
    winner = np.argmax(h, axis=0)
    # The support point in direction n = (cos, sin) is h n + h' n_perp (h' = dh/dtheta).
    value, slope = support_2d_with_derivative(centre[winner], k[winner], theta)
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([value * c - slope * s, value * s + slope * c], axis=-1)
