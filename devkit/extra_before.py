"""The extra measurements of a mannequin as ``core.measure.extra`` computed them before they were made faster
(each band searched apart by golden section, one hull_perimeter call per step; the arm's tip by a second
bisection; the neck, square to its axis since issue 26, by golden section too): tests check the two agree,
``bench.bench_extra`` times both in one run."""

import numpy as np

from ellimann_addon.core.constants import CM_PER_M
from ellimann_addon.core.geometry.ellipsoid import axis_extent, section_at_height
from ellimann_addon.core.measure.band_search import extreme_over_band
from ellimann_addon.core.measure.extra import (
    CALF_BAND,
    CROTCH_FLOOR,
    MID_PLANE_HEIGHT,
    SIDES,
    THIGH_DROP,
    UPPER_ARM_FRACTION,
    MannequinLandmarks,
    _permuted,
    mannequin_tilt,
)
from ellimann_addon.core.measure.neck import neck_band, neck_frame
from ellimann_addon.core.measure.tailor import hull_perimeter, section_heights
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS


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


class MannequinLandmarksBefore:
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
        heights = np.asarray(heights, float)
        centre, k, hit = section_at_height(self.rotation[None], self.center[None], self.semi[None], heights[:, None])
        return hull_perimeter(centre, k, hit & mask[None])

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


def mannequin_extra_measurements_before(mannequin):
    """The extra measurements of a mannequin (cm), {key: value} in EXTRA_MEASUREMENTS order; NaN where the
    mannequin has no such landmark (no arm parts, no crotch)."""
    marks = MannequinLandmarksBefore(mannequin)
    out = {}
    crotch = marks.crotch()
    out["crotch_height"] = crotch
    he = marks.height
    legs = [marks.leg_mask(side) for side in SIDES]
    if np.isfinite(crotch):
        z_thigh = marks.bottom + crotch - THIGH_DROP * he
        out["thigh"] = float(np.mean([marks.girths_at([z_thigh], mask)[0] for mask in legs]))
        low, high = (marks.bottom + f * crotch for f in CALF_BAND)
        out["calf"] = float(
            np.mean(
                [
                    extreme_over_band(lambda z, m=mask: marks.girths_at(z, m), low, high, True, marks.piece_ends(mask))
                    for mask in legs
                ]
            )
        )
    else:
        out["thigh"] = out["calf"] = np.nan
    # the whole section square to the neck's axis (the core's tilt and origin: the search is what is compared)
    frame, origin = neck_frame(mannequin_tilt(mannequin)), MannequinLandmarks(mannequin).neck_origin()
    rotation, center = frame @ marks.rotation, (marks.center - origin) @ frame.T
    half = axis_extent(rotation, marks.semi, 2)

    def neck_girths(offsets):
        offsets = np.asarray(offsets, float)
        centre, k, hit = section_at_height(rotation[None], center[None], marks.semi[None], offsets[:, None])
        girths = hull_perimeter(centre, k, hit)
        return np.where(girths > 0.0, girths, np.inf)

    out["neck"] = extreme_over_band(
        neck_girths,
        *neck_band(marks.height, mannequin_tilt(mannequin)),
        False,
        np.concatenate([center[:, 2] - half, center[:, 2] + half]),
    )
    out["neck"] = out["neck"] if np.isfinite(out["neck"]) else np.nan  # no piece in the neck's band: no neck
    if marks.arm.any() and all((marks.arm & (marks.side == side)).any() for side in SIDES):
        out["arm_length"] = float(np.mean([marks.arm_axis(side)[2] for side in SIDES]))
        out["upper_arm"] = float(np.mean([marks.arm_girth(side) for side in SIDES]))
    else:
        out["arm_length"] = out["upper_arm"] = np.nan
    return {key: out[key] * CM_PER_M for key in EXTRA_MEASUREMENTS}
