"""Dev-only references shared by tests and benchmarks: random mannequins and a brute-force m_T."""

import numpy as np
from scipy.spatial import ConvexHull

from ellimann_addon.core.constants import GIRTHS
from ellimann_addon.core.geometry.ellipsoid import section_at_height
from ellimann_addon.core.measure import tailor as measure
from ellimann_addon.core.measurements import MEASUREMENTS


def random_rotations(rng, n):
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


def random_mannequin_arrays(rng, n=40):
    """Random ellipsoids in a body-sized column (for m_T checks; not a body): r, c, d, girth."""
    rotation = random_rotations(rng, n)
    semi = rng.uniform(0.03, 0.15, size=(n, 3))
    center = np.stack([rng.normal(0, 0.12, n), rng.normal(0, 0.06, n), rng.uniform(0.1, 1.5, n)], -1)
    girth = rng.random(n) < 0.8
    return rotation, center, semi, girth


def brute_force_measure(rotation, center, semi_axes, girth, samples=20000):
    """m_T by dense sampling of each section ellipse's boundary + Qhull's 2D hull (cm).

    Independent of the Cauchy integration: only the closed-form section ellipse is shared.
    """
    _, height, z = measure.section_heights(rotation, center, semi_axes)
    t = np.linspace(0, 2 * np.pi, samples, endpoint=False)
    circle = np.stack([np.cos(t), np.sin(t)], -1)
    out = {"He": height * 100}
    for key in ("Sh",) + GIRTHS:
        c, k, hit = section_at_height(rotation, center, semi_axes, z[key])
        active = hit if key == "Sh" else hit & girth
        pts = []
        for i in np.nonzero(active)[0]:
            w, v = np.linalg.eigh(k[i])
            pts.append(c[i] + (circle * np.sqrt(np.clip(w, 0, None))) @ v.T)
        if not pts:
            out[key] = 0.0
            continue
        p = np.concatenate(pts)
        out[key] = 100 * (np.ptp(p[:, 0]) if key == "Sh" else ConvexHull(p).area)
    return np.array([out[m] for m in MEASUREMENTS])
