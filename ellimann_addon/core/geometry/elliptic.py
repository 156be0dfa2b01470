"""Elliptic integrals in numpy, elementwise: the incomplete integral of the second kind E(u | m) for any real u
(:func:`elliptic_e`), from Carlson's symmetric integrals R_F and R_D (:func:`carlson_rf_rd`, Carlson 1995). The
section hull integrates each ellipse's support between two kinks with it."""

import numpy as np

DUPLICATIONS = 8  # Carlson's duplication steps for the elliptic integrals (7 reach rounding; one to spare)


def elliptic_e(u, m):
    """The incomplete elliptic integral of the second kind E(u | m) = integral_0^u sqrt(1 - m sin^2 t) dt for any
    real u, 0 <= m < 1: E(k pi + r) = 2 k E(m) + E(r) with |r| <= pi / 2, E(r) = sin r R_F(cos^2 r, 1 - m sin^2 r, 1)
    - m/3 sin^3 r R_D(cos^2 r, 1 - m sin^2 r, 1) and the complete E(m) with r = pi / 2 (Carlson 1995, eq. 4.5).
    u (..., P) and m (P,): the angles of each m share its complete integral, computed only where a whole turn needs
    it (each value elementwise: the same bits whatever else is computed with it)."""
    u = np.asarray(u, dtype=float)
    turns = np.round(u / np.pi)
    r = u - turns * np.pi
    s, c = np.sin(r), np.cos(r)
    whole = np.nonzero((turns != 0.0).reshape(-1, len(m)).any(axis=0))[0]
    count = r.size
    rf, rd = carlson_rf_rd(
        np.concatenate([(c * c).ravel(), np.zeros(len(whole))]),
        np.concatenate([(1.0 - m * s * s).ravel(), 1.0 - m[whole]]),
    )
    complete = np.zeros(len(m))
    complete[whole] = rf[count:] - m[whole] / 3.0 * rd[count:]
    rf, rd = rf[:count].reshape(r.shape), rd[:count].reshape(r.shape)
    return s * rf - m / 3.0 * s * s * s * rd + 2.0 * turns * complete


def carlson_rf_rd(x, y):
    """Carlson's symmetric integrals R_F(x, y, 1) and R_D(x, y, 1), by DUPLICATIONS duplication steps (each shrinks
    the arguments' spread fourfold) and the series of Carlson 1995 (eqs. 2.7, 2.29): the same iterates serve both."""
    z = np.ones_like(x)
    total, scale = np.zeros_like(x), np.ones_like(x)
    for _ in range(DUPLICATIONS):
        sx, sy, sz = np.sqrt(x), np.sqrt(y), np.sqrt(z)
        lam = sx * (sy + sz) + sy * sz
        total += scale / (sz * (z + lam))
        scale *= 0.25
        x, y, z = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam)
    mean = (x + y + z) / 3.0
    dx, dy, dz = 1.0 - x / mean, 1.0 - y / mean, 1.0 - z / mean
    e2, e3 = dx * dy - dz * dz, dx * dy * dz
    rf = (1.0 + (e2 / 24.0 - 0.1 - 3.0 / 44.0 * e3) * e2 + e3 / 14.0) / np.sqrt(mean)
    mean = 0.2 * (x + y + 3.0 * z)
    dx, dy, dz = (mean - x) / mean, (mean - y) / mean, (mean - z) / mean
    ea, eb = dx * dy, dz * dz
    ec, ed = ea - eb, ea - 6.0 * eb
    ee = ed + 2.0 * ec
    series = (
        1.0
        + ed * (-3.0 / 14.0 + 9.0 / 88.0 * ed - 9.0 / 52.0 * dz * ee)
        + dz * (ee / 6.0 + dz * (-9.0 / 22.0 * ec + 3.0 / 26.0 * dz * ea))
    )
    return rf, 3.0 * total + scale * series / (mean * np.sqrt(mean))
