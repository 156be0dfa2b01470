"""The neck of a body mesh: the smallest whole section square to the neck's axis (``core.measure.neck``), the
axis leaning by a given tilt or by the tilt a tape drawn tight settles at; the sections cut from the triangles of
the band's slab, turned into the axis's frame (StandingBody's sections, turned)."""

import numpy as np

from ..geometry.mesh import hull_girth, section_segments
from .band_search import extreme_over_band
from .neck import NECK_BAND, NECK_TILT_DEFAULT, neck_band, neck_frame, tightest_tilt

NECK_SAMPLES = 96  # the neck's band (0.12 He) every 2 mm or so: a mannequin's pieces may pinch between them
NECK_STEPS = 20  # then golden section: the bracket of two cells narrows below a micrometre
# The tilt a tape settles at: the neck found at NECK_TILT_DEFAULT on a coarse grid, then at each tilt tried the
# smallest section within NECK_WINDOW He of it (the six bodies' lies within 0.012 He of it at 0-45 degrees), then
# the whole band at the tilt found: some 390 sections, not a whole band search per tilt.
NECK_FIRST_SAMPLES, NECK_FIRST_STEPS = 24, 10
NECK_WINDOW, NECK_WINDOW_STEPS = 0.02, 8  # He either side; golden steps: its bracket (0.027 He) to 0.001 He


class NeckSlices:
    """A body mesh's sections square to a neck axis leaning forward by ``tilt`` (radians) from ``origin``: the
    triangles that the band's planes can cross, in the axis's frame (StandingBody's sections, turned)."""

    def __init__(self, body, tilt, origin):
        self.frame, self.origin = neck_frame(tilt), origin
        self.band = neck_band(body.height, tilt)
        self.vertices = (body.vertices - origin) @ self.frame.T
        along = self.vertices[body.faces, 2]
        low, high = along.min(axis=1), along.max(axis=1)
        rows = np.nonzero((low < self.band[1]) & (high >= self.band[0]))[0]
        self.faces, self.low, self.high = body.faces[rows], low[rows], high[rows]

    def hull(self, offset):
        """(girth m, hull (k, 2) in the plane) of the section at ``offset`` along the axis."""
        crossed = (self.low < offset) & (self.high >= offset)
        return hull_girth(section_segments(self.vertices, self.faces[crossed], offset)[0].reshape(-1, 2))

    def girths(self, offsets):
        girths = np.array([self.hull(offset)[0] for offset in np.ravel(offsets)])
        return np.where(girths > 0.0, girths, np.inf)  # an empty section is no neck

    def smallest(self, low=None, high=None, samples=NECK_SAMPLES, steps=NECK_STEPS):
        """(smallest girth m, its offset) over the band, or over [low, high] within it."""
        low = self.band[0] if low is None else max(self.band[0], low)
        high = self.band[1] if high is None else min(self.band[1], high)
        return extreme_over_band(self.girths, low, high, False, samples=samples, where=True, steps=steps)

    def loop(self, offset):
        """The section's hull at ``offset`` as world points (k, 3)."""
        hull = self.hull(offset)[1]
        return self.origin + np.c_[hull, np.full(len(hull), offset)] @ self.frame


def neck_origin(body):
    """The neck axis's point at the soles' height (MannequinLandmarks.neck_origin on a mesh)."""
    segments, _ = body.section(body.at(np.mean(NECK_BAND)))
    y = segments[:, :, 1] if len(segments) else body.vertices[:, 1]
    return np.array([0.0, 0.5 * (y.min() + y.max()), body.bottom])


def body_neck(body, tilt=None):
    """(neck girth m, tilt radians, its loop (k, 3)) of a StandingBody: the smallest section square to the neck's
    axis leaning forward by ``tilt``, by default the tilt at which that is smallest (a tape drawn tight)."""
    origin = neck_origin(body)
    if tilt is None:
        first = np.radians(NECK_TILT_DEFAULT)
        _, offset = NeckSlices(body, first, origin).smallest(samples=NECK_FIRST_SAMPLES, steps=NECK_FIRST_STEPS)
        height, window = offset / np.cos(first), NECK_WINDOW * body.height  # along the axis, above the soles

        def smallest(tilts):
            return np.array(
                [
                    NeckSlices(body, t, origin).smallest(
                        height * np.cos(t) - window, height * np.cos(t) + window, 4, NECK_WINDOW_STEPS
                    )[0]
                    for t in np.ravel(tilts)
                ]
            )

        _, tilt = tightest_tilt(smallest)
    slices = NeckSlices(body, tilt, origin)
    girth, offset = slices.smallest()
    return girth, float(tilt), slices.loop(offset) if np.isfinite(girth) else np.zeros((0, 3))
