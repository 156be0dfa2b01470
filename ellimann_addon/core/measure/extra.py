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
- neck: the smallest girth of the whole section square to the neck's axis, among the planes crossing the axis
  between ``NECK_BAND`` He (``core.measure.neck``: the axis leans forward as the Neck -> Head joints do, by
  ``NECK_TILT_DEFAULT`` without joints; a body mesh's by the tilt a tape drawn tight settles at);
- arm_length: shoulder point to fingertip (straight, the arm as it hangs in the A-pose);
- upper_arm: the arm's girth across its axis (shoulder point to fingertip) at ``UPPER_ARM_FRACTION`` of it.
A girth is the perimeter of the convex hull of a section (a tape measure), as m_T's; both legs or arms are
measured and their mean reported.
"""

import numpy as np

from ..constants import CM_PER_M
from ..geometry.ellipsoid import axis_extent, section_at_height
from ..measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from .band_search import BAND_SAMPLES, extremes_over_bands
from .neck import NECK_BAND, NECK_TILT_DEFAULT, joint_tilt, neck_band, neck_frame, tightest_tilt
from .tailor import hull_perimeter, section_heights

MID_PLANE_HEIGHT = 0.25  # He: where x_c is taken
CROTCH_FLOOR = 0.2  # He: the crotch is searched above this
THIGH_DROP = 0.02  # He below the crotch
CALF_BAND = (0.25, 0.6)  # fractions of the crotch height
UPPER_ARM_FRACTION = 0.25  # of the shoulder-to-fingertip axis, from the shoulder
GIRTH_CHUNK = 48  # sections per hull_perimeter call
SIDES = ("L", "R")


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
        return self.along(np.stack([first, np.cross(axis, first), axis]), start)

    def along(self, frame, origin):
        """(rotation, center) of every ellipsoid in the frame of rows ``frame`` about ``origin``: its sections
        square to the frame's third axis are horizontal ones there, at the offset along that axis."""
        return frame @ self.rotation, (self.center - origin) @ frame.T

    def neck_origin(self):
        """The neck axis's point at the soles' height, below the middle of the body's front-to-back extent at the
        neck band's middle (of the whole body's where that section is empty)."""
        centre, k, hit = section_at_height(self.rotation, self.center, self.semi, self.at(np.mean(NECK_BAND)))
        if hit.any():
            y, half = centre[hit, 1], np.sqrt(k[hit, 1, 1])
        else:
            y, half = self.center[:, 1], axis_extent(self.rotation, self.semi, 1)
        return np.array([0.0, 0.5 * ((y - half).min() + (y + half).max()), self.bottom])


class _GirthFamilies:
    """Girths as functions of one parameter each, evaluated together in one hull_perimeter call: horizontal
    sections of the ellipsoids ``masks[f]`` at a height, then sections in frames of their own (``framed``: (frame
    rotation, center, mask) each, as ``MannequinLandmarks.along`` gives them: across each arm, square to the
    neck) at an offset along the frame's third axis. Infinity where a family of ``empty_is_none`` has an empty
    section (a smallest girth never lies there)."""

    def __init__(self, marks, masks, framed, empty_is_none=()):
        self.marks, self.masks, self.framed, self.empty_is_none = marks, np.asarray(masks), framed, list(empty_is_none)

    def __call__(self, family, parameter):
        family, parameter = np.asarray(family, int), np.asarray(parameter, float)
        horizontal, count = len(self.masks), len(self.marks.semi)
        centre, k = np.zeros((len(family), count, 2)), np.zeros((len(family), count, 2, 2))
        active = np.zeros((len(family), count), bool)
        rows = np.nonzero(family < horizontal)[0]
        if len(rows):
            centre[rows], k[rows], hit = self.marks.sections_at(parameter[rows])
            active[rows] = hit & self.masks[family[rows]]
        for index, (rotation, center, mask) in enumerate(self.framed):
            rows = np.nonzero(family == horizontal + index)[0]
            if len(rows):
                centre[rows], k[rows], hit = section_at_height(
                    rotation[None], center[None], self.marks.semi[None], parameter[rows, None]
                )
                active[rows] = hit & mask
        girths = _chunked_hull_perimeter(centre, k, active)
        return np.where(np.isin(family, self.empty_is_none) & (girths <= 0.0), np.inf, girths)


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


def _neck_sections(marks, origin, tilts):
    """The sections square to the neck at each tilt (radians): (framed families, bands (low, high, piece ends))."""
    framed, bands = [], []
    for tilt in tilts:
        rotation, center = marks.along(neck_frame(tilt), origin)
        half = axis_extent(rotation, marks.semi, 2)
        framed.append((rotation, center, np.ones(len(center), bool)))  # the whole section
        bands.append((*neck_band(marks.height, tilt), np.concatenate([center[:, 2] - half, center[:, 2] + half])))
    return framed, bands


def _smallest_necks(marks, origin, tilts):
    """The smallest girth (m) square to the neck at each tilt (radians; infinity where the band is empty)."""
    framed, bands = _neck_sections(marks, origin, tilts)
    families = _GirthFamilies(marks, [], framed, range(len(tilts)))
    return np.array(
        extremes_over_bands(families, [(i, *band, False, ends) for i, (*band, ends) in enumerate(bands)])[0]
    )


def mannequin_tilt(mannequin):
    """The forward tilt (radians) of a mannequin's neck: its Neck -> Head joints', else NECK_TILT_DEFAULT."""
    tilt = joint_tilt(mannequin.joints)
    return np.radians(NECK_TILT_DEFAULT) if tilt is None else tilt


def mannequin_neck(mannequin, tilt=None, marks=None):
    """(neck girth m, tilt radians, the axis's origin (3,)): the smallest section square to the neck's axis at
    ``tilt`` (default the mannequin's own: ``mannequin_tilt``)."""
    marks = marks or MannequinLandmarks(mannequin)
    origin = marks.neck_origin()
    tilt = mannequin_tilt(mannequin) if tilt is None else float(tilt)
    return float(_smallest_necks(marks, origin, [tilt])[0]), tilt, origin


def neck_plane(mannequin, samples=BAND_SAMPLES):
    """(frame rows, origin, offset) of the plane square to the neck's axis where the girth is smallest on a grid of
    ``samples`` over the band (enough to pick the pieces a deformation widens there)."""
    marks = MannequinLandmarks(mannequin)
    origin, tilt = marks.neck_origin(), mannequin_tilt(mannequin)
    framed, ((low, high, _),) = _neck_sections(marks, origin, [tilt])
    offsets = np.linspace(low, high, samples)
    girths = _GirthFamilies(marks, [], framed, [0])(np.zeros(samples, int), offsets)
    return neck_frame(tilt), origin, offsets[int(np.argmin(girths))]


def tightest_mannequin_neck(mannequin, marks=None):
    """mannequin_neck at the tilt a tape drawn tight settles at, as a body mesh is measured (its pieces' own
    shape, whatever its joints say)."""
    marks = marks or MannequinLandmarks(mannequin)
    origin = marks.neck_origin()
    girth, tilt = tightest_tilt(lambda tilts: _smallest_necks(marks, origin, tilts))
    return girth, tilt, origin


def mannequin_extra_measurements(mannequin):
    """The extra measurements of a mannequin (cm), {key: value} in EXTRA_MEASUREMENTS order; NaN where the
    mannequin has no such landmark (no arm parts, no crotch). Every girth in one band search: the calves' and
    the neck's bands refined together, the thighs' and upper arms' sections measured with their grids."""
    marks = MannequinLandmarks(mannequin)
    crotch = marks.crotch()
    legs = [marks.leg_mask(side) for side in SIDES]
    has_arms = all(marks.arm_mask(side).any() for side in SIDES)
    axes = marks.arm_axes() if has_arms else []
    arms = [(*marks.across_arm(side, start, axis), marks.arm_mask(side)) for side, (start, axis, _) in zip(SIDES, axes)]
    necks, neck_bands = _neck_sections(marks, marks.neck_origin(), [mannequin_tilt(mannequin)])
    first_neck = len(legs) + len(arms)
    families = _GirthFamilies(marks, legs, arms + necks, [first_neck])  # the legs, the arms, then the neck
    bands = [(first_neck, low, high, False, ends) for low, high, ends in neck_bands]
    points = [(len(legs) + i, UPPER_ARM_FRACTION * length) for i, (_, _, length) in enumerate(axes)]
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
