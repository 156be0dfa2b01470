"""The six extra measurements of a body of the set's topology, fast: ``measure_body_mesh``'s definitions and its
own steps (its StandingBody, crotch, leg girths, neck slices, arm readings), with what the fixed topology knows:

- the arms from the labels (as the whole measurer is given them);
- the calf's girths from each leg's own triangles (the labels' thigh, shin and foot of that side): below the
  crotch a leg's section is its own loop, the one the measurer's blobs pick for that side, so the segments are the
  same ones, in the same order (checked per reading: any other triangle in the calf's band, or a leg across the
  mid-plane, and the measurer's own leg girth is used);
- the crotch from the triangles that cross the mid-plane only (the same segments);
- the neck square to a given tilt, or at the tilt a tape drawn tight settles at (``measure``'s search) when none
  is given; the correction's loop holds the last whole reading's tilt (``Marks.tilt``), since a tilt searched
  anew each round jumps between nearby bodies.

``read(..., marks=None)`` searches every band as the measurer does (its samples, its golden steps): the same numbers as
``measure_body_mesh(vertices, faces, fractions, neck_tilt, arms)`` (tests/core/body/test_body_extra_tape.py, on the
bank's bodies). With ``marks`` (where the last reading found the calf's and the neck's extremes) it searches only a
window about them (WINDOW_SAMPLES and WINDOW_STEPS): the correction's loop, whose bodies move by millimetres between
readings; an extreme's value is insensitive to where exactly it is found.
"""

from dataclasses import dataclass, field

import numpy as np

from ..constants import CM_PER_M
from ..geometry.mesh import hull_girth, section_segments
from ..measure.band_search import extreme_over_band
from ..measure.body import StandingBody, arm_reading
from ..measure.body_neck import NeckSlices, body_neck, neck_origin
from ..measure.extra import CALF_BAND, CROTCH_FLOOR, SIDES, THIGH_DROP
from ..measurements import EXTRA_MEASUREMENTS

LEG_REGIONS = ("thigh", "shin", "foot")
# the loop's reading of an extreme: the measurer's band search in a window about the last one (He along the neck's
# axis, the crotch's height for the calf), fewer samples and golden steps: a girth over a mesh is kinky, its
# largest value a spike that a window finds again where a parabola through samples falls short by millimetres
WINDOW = {"neck": 0.01, "calf": 0.01}
WINDOW_SAMPLES, WINDOW_STEPS = 3, 8
COARSE_SAMPLES, COARSE_STEPS = 12, 8  # a first reading's whole band, coarser than the measurer's


@dataclass
class Marks:
    """Where a reading found the extremes: the neck's offset along its axis (fraction of He) and the tilt it was
    square to (radians), and each calf's height (fraction of the crotch's height)."""

    neck: float = float("nan")
    tilt: float = float("nan")
    calf: dict = field(default_factory=dict)


def leg_masks(region, region_names):
    """{"L", "R": (V,) bool} each leg's vertices (thigh, shin, foot) from the labels."""
    names = list(region_names)
    return {
        side: np.isin(region, [names.index(f"{r}_{side}") for r in LEG_REGIONS if f"{r}_{side}" in names])
        for side in SIDES
    }


class ExtraTape:
    """Reads the six extras of bodies of one topology (``faces``), ``arms`` and ``legs`` ({"L", "R": (V,) bool})
    from the labels, at the section heights ``fractions``."""

    def __init__(self, faces, arms, legs, fractions):
        self.faces = np.asarray(faces, np.int64)
        self.fractions = dict(fractions)
        self.arms = {side: np.asarray(arms[side], bool) for side in SIDES}
        self.arm_faces = {side: self.arms[side][self.faces].all(axis=1) for side in SIDES}
        arm = self.arms["L"] | self.arms["R"]
        self.leg_rows = np.nonzero(~arm[self.faces].any(axis=1))[0]  # the measurer's leg_rows
        self.leg_faces = {side: np.nonzero(legs[side][self.faces].all(axis=1))[0] for side in SIDES}
        own = np.zeros(len(self.faces), bool)
        for side in SIDES:
            own[self.leg_faces[side]] = True
        self.other_rows = self.leg_rows[~own[self.leg_rows]]  # leg_rows that are no leg's own triangles

    def read(self, vertices, keys, tilt=None, marks=None, coarse=False):
        """({key: cm} of the extras among ``keys``, Marks): the neck square to ``tilt`` (radians; None: searched as
        the measurer does), every band searched whole as the measurer does (``marks`` None), coarser
        (``coarse``: COARSE_SAMPLES and COARSE_STEPS, a first reading that only needs to find the extremes) or in
        a window about ``marks``."""
        search = dict(samples=COARSE_SAMPLES, steps=COARSE_STEPS) if coarse else {}
        body = StandingBody(vertices, self.faces, self.fractions)
        wanted = [key for key in EXTRA_MEASUREMENTS if key in keys]
        values, found = {}, Marks()
        if {"crotch_height", "thigh", "calf"} & set(wanted):
            crotch = self._crotch(body)
            values["crotch_height"] = crotch
            if np.isfinite(crotch):
                if "thigh" in wanted:
                    z = body.bottom + crotch - THIGH_DROP * body.height
                    values["thigh"] = float(np.mean([body.leg_girth(z, side, self.leg_rows)[0] for side in SIDES]))
                if "calf" in wanted:
                    values["calf"], found.calf = self._calf(body, crotch, marks, search)
        if "neck" in wanted:
            values["neck"], found.neck, found.tilt = self._neck(body, tilt, marks, search)
        if {"upper_arm", "arm_length"} & set(wanted):
            z_sh = body.at(body.fractions["Sh"])
            readings = [arm_reading(body, s, z_sh, self.arms[s], self.arm_faces[s]) for s in SIDES]
            values["arm_length"] = float(np.mean([reading[2] for reading in readings]))
            values["upper_arm"] = float(np.mean([reading[3] for reading in readings]))
        return {key: float(values.get(key, np.nan)) * CM_PER_M for key in wanted}, found

    def _crotch(self, body):
        """StandingBody.crotch on the triangles crossing the mid-plane (the same segments, fewer triangles)."""
        x = body.vertices[self.faces, 0] - body.mid_x
        rows = np.nonzero((x.min(axis=1) < 0.0) & (x.max(axis=1) >= 0.0))[0]
        turned = np.stack([body.vertices[:, 1], body.vertices[:, 2], body.vertices[:, 0] - body.mid_x], axis=1)
        points = section_segments(turned, self.faces[rows], 0.0)[0].reshape(-1, 2)
        points = points[points[:, 1] > body.at(CROTCH_FLOOR)]
        return float(points[:, 1].min() - body.bottom) if len(points) else np.nan

    def _calf(self, body, crotch, marks, search):
        """(mean of the two calves' largest girths over CALF_BAND of the crotch's height, {side: where})."""
        low, high = (body.bottom + f * crotch for f in CALF_BAND)
        own = self.legs_apart(body, low, high)
        out, where = [], {}
        for side in SIDES:

            def girths(heights, side=side):
                if own:
                    return np.array([self._own_leg_girth(body, z, side) for z in np.ravel(heights)])
                return np.array([body.leg_girth(z, side, self.leg_rows)[0] for z in np.ravel(heights)])

            if marks is not None and side in marks.calf:
                centre = body.bottom + marks.calf[side] * crotch
                a, b = max(low, centre - WINDOW["calf"] * crotch), min(high, centre + WINDOW["calf"] * crotch)
                value, at = extreme_over_band(
                    girths, a, b, True, samples=WINDOW_SAMPLES, where=True, steps=WINDOW_STEPS
                )
            else:
                value, at = extreme_over_band(girths, low, high, True, where=True, **search)
            out.append(value)
            where[side] = (at - body.bottom) / crotch
        return float(np.mean(out)), where

    def legs_apart(self, body, low, high):
        """Whether between heights ``low`` and ``high`` the section of the measurer's leg triangles is each leg's
        own triangles only, each leg on its side of the mid-plane."""
        z = body.vertices[self.faces[self.other_rows], 2]
        if np.any((z.max(axis=1) >= low) & (z.min(axis=1) < high)):
            return False
        for side, sign in zip(SIDES, (1.0, -1.0)):
            z = body.vertices[self.faces[self.leg_faces[side]], 2]
            near = self.leg_faces[side][(z.max(axis=1) >= low) & (z.min(axis=1) < high)]
            if np.any(sign * (body.vertices[self.faces[near], 0] - body.mid_x) <= 0.0):
                return False
        return True

    def _own_leg_girth(self, body, z, side):
        crossed = body.crossed(z, self.leg_faces[side])
        return hull_girth(section_segments(body.vertices, self.faces[crossed], z)[0].reshape(-1, 2))[0]

    def _neck(self, body, tilt, marks, search):
        """(smallest girth square to the axis at ``tilt``, its offset / He, the tilt): body_neck's search, or a
        window."""
        if tilt is None:
            tilt = body_neck(body)[1]
        slices = NeckSlices(body, tilt, neck_origin(body))
        if marks is not None and np.isfinite(marks.neck):
            low, high = ((marks.neck + side * WINDOW["neck"]) * body.height for side in (-1.0, 1.0))
            girth, offset = slices.smallest(low, high, WINDOW_SAMPLES, WINDOW_STEPS)
        else:
            girth, offset = slices.smallest(**search)
        return girth, offset / body.height, float(tilt)
