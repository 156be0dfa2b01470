"""The measurements beyond the paper's five: names, labels, where each is taken, and their closed forms on a
mannequin's ellipsoids (``docs/measurements.md``; a body mesh is measured the same way by ``core.body_measure``).

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

from .constants import CM_PER_M
from .ellipsoid import axis_extent, section_at_height
from .measure import hull_perimeter, section_heights

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
EXTRA_ABSURD_LIMITS = {"neck": (15.0, 80.0), "upper_arm": (10.0, 80.0), "thigh": (20.0, 140.0),
                       "calf": (15.0, 90.0), "crotch_height": (20.0, 130.0), "arm_length": (20.0, 120.0)}
# What the female Average Reference Mannequin measures (cm): the panel's starting values.
EXTRA_DEFAULTS = {"neck": 32.4, "upper_arm": 23.6, "thigh": 56.0, "calf": 42.6, "crotch_height": 72.0,
                  "arm_length": 57.8}
# ISO 20685 allowances (cm): how far two ways of measuring one body may differ.
ISO_ALLOWANCE = {"He": 0.4, "Sh": 0.4, "Br": 0.9, "Wa": 0.9, "Hi": 0.9, "neck": 0.9, "upper_arm": 0.9,
                 "thigh": 0.9, "calf": 0.9, "crotch_height": 0.4, "arm_length": 0.4}

MID_PLANE_HEIGHT = 0.25  # He: where x_c is taken
CROTCH_FLOOR = 0.2  # He: the crotch is searched above this
THIGH_DROP = 0.02  # He below the crotch
CALF_BAND = (0.25, 0.6)  # fractions of the crotch height
NECK_BAND = (0.80, 0.92)  # fractions of He
UPPER_ARM_FRACTION = 0.25  # of the shoulder-to-fingertip axis, from the shoulder
BAND_SAMPLES = 48  # grid over a band before the extreme is refined
GOLDEN_STEPS = 40  # golden-section steps: the band's grid cell shrinks below a micrometre
SIDES = ("L", "R")


def extreme_over_band(function, low, high, largest, breaks=(), samples=BAND_SAMPLES, where=False):
    """Largest (or smallest) value of a 1-D ``function`` (vectorised over an array of heights) on [low, high].

    The band is cut at ``breaks`` (where the function may have a kink or a narrow dip: the ends of the pieces
    a mannequin's section meets) and each piece sampled on a grid; golden-section search then refines every
    grid cell beside a piece's best sample, all pieces at once, and the best of everything is returned."""
    cuts = np.unique(np.clip(np.concatenate([[low, high], np.asarray(breaks, float)]), low, high))
    per_piece = max(4, samples // max(len(cuts) - 1, 1))
    t = np.linspace(0.0, 1.0, per_piece)
    grid = cuts[:-1, None] + (cuts[1:] - cuts[:-1])[:, None] * t  # (P, per_piece)
    sign = -1.0 if largest else 1.0
    values = sign * function(grid.ravel()).reshape(grid.shape)
    best = np.argmin(values, axis=1)
    rows = np.arange(len(grid))
    a = grid[rows, np.maximum(best - 1, 0)]
    b = grid[rows, np.minimum(best + 1, per_piece - 1)]
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


def _permuted(rotation, center, order):
    """Ellipsoids seen in axes ``order`` (a permutation of 0, 1, 2): world axis order[2] becomes 'up'."""
    p = np.eye(3)[list(order)]
    return p @ rotation, center @ p.T


def _farthest_distance(rotation, center, semi_axes, point):
    """Largest distance from ``point`` to each ellipsoid (n,): the secular equation of the farthest point,
    solved by bisection on its monotone branch (mu > the largest squared semi-axis)."""
    local = np.einsum("nji,nj->ni", rotation, point - center)  # R^T (p - c)
    a2 = semi_axes**2
    low = a2.max(axis=1)
    high = low + (np.linalg.norm(local, axis=1) + semi_axes.max(axis=1)) * semi_axes.max(axis=1) * 4.0 + 1e-12
    for _ in range(100):
        mu = 0.5 * (low + high)
        value = np.sum((semi_axes * local / (a2 - mu[:, None])) ** 2, axis=1)
        outside = value > 1.0
        low, high = np.where(outside, mu, low), np.where(outside, high, mu)
    mu = 0.5 * (low + high)
    surface = a2 * local / (a2 - mu[:, None])
    return np.linalg.norm(surface - local, axis=1)


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
        self.mid_x = 0.5 * (np.max(np.where(hit, centre[:, 0] + half, -np.inf))
                            + np.min(np.where(hit, centre[:, 0] - half, np.inf)))

    def at(self, fraction):
        return self.bottom + fraction * self.height

    def piece_ends(self, mask):
        """Lowest and highest z of the ellipsoids ``mask``: where a section gains or loses a piece."""
        half = axis_extent(self.rotation[mask], self.semi[mask], 2)
        return np.concatenate([self.center[mask, 2] - half, self.center[mask, 2] + half])

    def girths_at(self, heights, mask):
        """Hull perimeter (m) of the sections of the ellipsoids ``mask`` at each height (array)."""
        heights = np.asarray(heights, float)
        centre, k, hit = section_at_height(self.rotation[None], self.center[None], self.semi[None], heights[:, None])
        return hull_perimeter(centre, k, hit & mask[None])

    def nonzero_girths_at(self, heights, mask):
        """As girths_at, with infinity where the section is empty (a smallest girth never lies there)."""
        girths = self.girths_at(heights, mask)
        return np.where(girths > 0.0, girths, np.inf)

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

    def arm_axis(self, side):
        """(shoulder point, unit axis, length m): from the shoulder point to the arm's farthest point."""
        start = self.shoulder_point(side)
        mask = self.arm & (self.side == side)
        rotation, center, semi = self.rotation[mask], self.center[mask], self.semi[mask]
        reach = _farthest_distance(rotation, center, semi, start)
        i = int(np.argmax(reach))
        # the farthest point lies along the ellipsoid's support direction from start; recover it exactly
        local = rotation[i].T @ (start - center[i])
        a2 = semi[i] ** 2
        low, high = a2.max(), a2.max() + 10.0
        for _ in range(100):
            mu = 0.5 * (low + high)
            value = np.sum((semi[i] * local / (a2 - mu)) ** 2)
            low, high = (mu, high) if value > 1.0 else (low, mu)
        tip = center[i] + rotation[i] @ (a2 * local / (a2 - 0.5 * (low + high)))
        return start, (tip - start) / reach[i], float(reach[i])

    def arm_girth(self, side):
        start, axis, length = self.arm_axis(side)
        origin = start + UPPER_ARM_FRACTION * length * axis
        helper = np.array([0.0, 0.0, 1.0]) if abs(axis[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        first = np.cross(helper, axis)
        first /= np.linalg.norm(first)
        frame = np.stack([first, np.cross(axis, first), axis])
        mask = self.arm & (self.side == side)
        rotation = frame @ self.rotation[mask]
        center = (self.center[mask] - origin) @ frame.T
        centre, k, hit = section_at_height(rotation, center, self.semi[mask], 0.0)
        return float(hull_perimeter(centre[None], k[None], hit[None])[0])


def mannequin_extra_measurements(mannequin):
    """The extra measurements of a mannequin (cm), {key: value} in EXTRA_MEASUREMENTS order; NaN where the
    mannequin has no such landmark (no arm parts, no crotch)."""
    marks = MannequinLandmarks(mannequin)
    out = {}
    crotch = marks.crotch()
    out["crotch_height"] = crotch
    he = marks.height
    legs = [marks.leg_mask(side) for side in SIDES]
    if np.isfinite(crotch):
        z_thigh = marks.bottom + crotch - THIGH_DROP * he
        out["thigh"] = float(np.mean([marks.girths_at([z_thigh], mask)[0] for mask in legs]))
        low, high = (marks.bottom + f * crotch for f in CALF_BAND)
        out["calf"] = float(np.mean([extreme_over_band(lambda z, m=mask: marks.girths_at(z, m), low, high, True,
                                                       marks.piece_ends(mask)) for mask in legs]))
    else:
        out["thigh"] = out["calf"] = np.nan
    neck_mask = np.ones(len(marks.girth), bool)  # the whole section: no arm reaches the neck's band apart
    out["neck"] = extreme_over_band(lambda z: marks.nonzero_girths_at(z, neck_mask), *(marks.at(f) for f in NECK_BAND),
                                    False, marks.piece_ends(neck_mask))
    out["neck"] = out["neck"] if np.isfinite(out["neck"]) else np.nan  # no piece in the neck's band: no neck
    if marks.arm.any() and all((marks.arm & (marks.side == side)).any() for side in SIDES):
        out["arm_length"] = float(np.mean([marks.arm_axis(side)[2] for side in SIDES]))
        out["upper_arm"] = float(np.mean([marks.arm_girth(side) for side in SIDES]))
    else:
        out["arm_length"] = out["upper_arm"] = np.nan
    return {key: out[key] * CM_PER_M for key in EXTRA_MEASUREMENTS}


