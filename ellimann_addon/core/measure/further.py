"""Measurements a tape takes beyond the eleven (the five and the six extras), taken on a body mesh: inputs that
tell a body model (core.body.ridge) how girth is shared between front and back, breast and belly, hip and thigh,
and where the limbs narrow. They are read on a mesh only (a scan, a body of a set); no mannequin's pieces and no
correction aim at them: a body model takes them as inputs ("they inform the shape"), docs/body_space.md.

Landmarks as core.measure.extra's (A-pose, the body faces -Y, +X its left, Z up; fractions of He above the
soles; the arms from the labels or found by geometry, core.measure.body); the torso's section at a height is the
section of the triangles not wholly an arm's (as the five's girths). Measurements (cm):

- bust_height: the bust point's height: the torso's most forward point (least y) within ``BUST_BAND`` He of the
  Br section;
- underbust: the torso's girth at the underbust: the height between ``UNDERBUST_BAND`` He below the bust point
  where the torso's front lies farthest back (the fold under the breasts; on a flat chest the band's foot);
- high_hip: the torso's girth midway between the Wa and Hi sections;
- bust_depth, waist_depth, hip_depth: the torso's front-to-back extent (along Y) at the Br, Wa and Hi sections;
- knee: one leg's girth at ``KNEE_FRACTION`` of the crotch height (the knee joint's level on the reference bodies:
  0.625-0.645 of it);
- ankle: the smallest girth of one leg between ``ANKLE_BAND`` of the crotch height (above the ankle bones);
- wrist: the smallest girth of the arm across its axis (shoulder point to fingertip) between ``WRIST_BAND`` of the
  axis (the wrist joint lies at 0.70-0.71 of it);
- shoulder_to_wrist: from the shoulder point to the wrist's section, along the arm's axis.
A girth is the perimeter of the convex hull of its section (a tape); both legs and arms are measured and their
mean reported.
"""

import numpy as np

from ..constants import CM_PER_M
from ..geometry.mesh import hull_girth, in_plane
from .band_search import extreme_over_band
from .body import StandingBody, section_blobs
from .extra import SIDES

FURTHER_MEASUREMENTS = (
    "underbust",
    "high_hip",
    "bust_depth",
    "waist_depth",
    "hip_depth",
    "bust_height",
    "knee",
    "ankle",
    "wrist",
    "shoulder_to_wrist",
)
FURTHER_LABELS = {
    "underbust": "Underbust girth",
    "high_hip": "High-hip girth",
    "bust_depth": "Bust depth",
    "waist_depth": "Waist depth",
    "hip_depth": "Hip depth",
    "bust_height": "Bust height",
    "knee": "Knee girth",
    "ankle": "Ankle girth",
    "wrist": "Wrist girth",
    "shoulder_to_wrist": "Shoulder to wrist",
}
# ISO 20685's classes of allowance (cm): girths 9 mm, depths and breadths 5 mm, heights and lengths 4 mm
FURTHER_ALLOWANCE = {
    "underbust": 0.9,
    "high_hip": 0.9,
    "bust_depth": 0.5,
    "waist_depth": 0.5,
    "hip_depth": 0.5,
    "bust_height": 0.4,
    "knee": 0.9,
    "ankle": 0.9,
    "wrist": 0.9,
    "shoulder_to_wrist": 0.4,
}
FURTHER_ABSURD_LIMITS = {
    "underbust": (40.0, 250.0),
    "high_hip": (40.0, 250.0),
    "bust_depth": (10.0, 90.0),
    "waist_depth": (8.0, 90.0),
    "hip_depth": (10.0, 90.0),
    "bust_height": (60.0, 200.0),
    "knee": (20.0, 90.0),
    "ankle": (12.0, 60.0),
    "wrist": (8.0, 40.0),
    "shoulder_to_wrist": (25.0, 100.0),
}
BUST_BAND = 0.05  # He either side of the Br section
UNDERBUST_BAND = (0.06, 0.01)  # He below the bust point: where the underbust is searched
KNEE_FRACTION = 0.64  # of the crotch height
ANKLE_BAND = (0.12, 0.30)  # of the crotch height
WRIST_BAND = (0.62, 0.72)  # of the shoulder-to-fingertip axis
SEARCH_STEPS = 24  # golden-section steps of a band search (the bracket below a micrometre)


def measure_further(vertices, faces, fractions=None, arms=None):
    """({key: cm} of FURTHER_MEASUREMENTS that could be taken, [problems, one line each]) of an upright A-pose body
    mesh (metres, Z up, facing -Y) at the section heights ``fractions``; ``arms`` {"L", "R": (V,) bool} when known
    (a set's labels), else found by geometry."""
    body = StandingBody(vertices, faces, fractions)
    if arms is None:
        armpit, arms = body.find_arms()
        if any(armpit[side] is None or not arms[side].any() for side in SIDES):
            return {}, ["the arms are against the torso (no gap beside the waist section): nothing further taken"]
    arm_vertex = {side: np.asarray(arms[side], bool) for side in SIDES}
    any_arm = arm_vertex["L"] | arm_vertex["R"]
    arm_faces = {side: arm_vertex[side][body.faces].all(axis=1) for side in SIDES}
    torso_rows = np.nonzero(~(arm_faces["L"] | arm_faces["R"]))[0]
    values, problems = {}, []
    values.update(_torso(body, torso_rows, any_arm, problems))
    values.update(_legs(body, np.nonzero(~any_arm[body.faces].any(axis=1))[0], problems))
    values.update(_wrists(body, arm_vertex, arm_faces, problems))
    return {key: float(values[key]) * CM_PER_M for key in FURTHER_MEASUREMENTS if key in values}, problems


def _torso(body, rows, any_arm, problems):
    """underbust, high_hip, the depths and bust_height (m)."""
    out = {}

    def section(z):
        return body.section(z, rows)[0].reshape(-1, 2)

    for key, depth in (("Br", "bust_depth"), ("Wa", "waist_depth"), ("Hi", "hip_depth")):
        points = section(body.at(body.fractions[key]))
        if len(points):
            out[depth] = float(np.ptp(points[:, 1]))
    z_high = body.at(0.5 * (body.fractions["Wa"] + body.fractions["Hi"]))
    out["high_hip"] = hull_girth(section(z_high))[0]
    z = body.vertices[:, 2]
    band = ~any_arm & (np.abs(z - body.at(body.fractions["Br"])) <= BUST_BAND * body.height)
    if not band.any():
        problems.append("no torso near the Br section: bust_height and underbust cannot be taken")
        return out
    bust = np.nonzero(band)[0][np.argmin(body.vertices[band, 1])]
    out["bust_height"] = float(z[bust] - body.bottom)

    def front(heights):
        return np.array([np.min(p[:, 1]) if len(p := section(h)) else -np.inf for h in np.atleast_1d(heights)])

    low, high = (z[bust] - f * body.height for f in UNDERBUST_BAND)
    _, fold = extreme_over_band(front, low, high, True, where=True, steps=SEARCH_STEPS)
    out["underbust"] = hull_girth(section(fold))[0]
    return out


def _legs(body, leg_rows, problems):
    """knee and ankle (m), each the mean of both legs."""
    crotch = body.crotch()
    if not np.isfinite(crotch):
        problems.append("no crotch (the legs are not apart at the mid-plane): knee and ankle cannot be taken")
        return {}
    out = {"knee": np.mean([body.leg_girth(body.bottom + KNEE_FRACTION * crotch, s, leg_rows)[0] for s in SIDES])}
    low, high = (body.bottom + f * crotch for f in ANKLE_BAND)

    def girths(side):
        return lambda heights: np.array([body.leg_girth(h, side, leg_rows)[0] for h in np.atleast_1d(heights)])

    out["ankle"] = np.mean([extreme_over_band(girths(s), low, high, False, steps=SEARCH_STEPS) for s in SIDES])
    return out


def shoulder_point(body, side):
    """The outermost point of the Sh section on ``side`` (core.measure.extra's landmark)."""
    z = body.at(body.fractions["Sh"])
    points = body.section(z)[0].reshape(-1, 2)
    i = int(np.argmax(points[:, 0] if side == "L" else -points[:, 0]))
    return np.array([points[i, 0], points[i, 1], z])


def arm_girth(body, arm_faces, start, axis, offset):
    """The arm's girth (m) across ``axis`` at ``offset`` m from ``start``: the section's loop around the axis (the
    one nearest to it when none holds it)."""
    moved, _ = in_plane(body.vertices, start + offset * axis, axis)
    segments, _, blob = section_blobs(moved, body.faces[arm_faces], 0.0)
    if len(segments) == 0:
        return np.inf
    labels = np.unique(blob)
    distance = [np.linalg.norm(segments[blob == b].reshape(-1, 2).mean(axis=0)) for b in labels]
    return hull_girth(segments[blob == labels[int(np.argmin(distance))]].reshape(-1, 2))[0]


def _wrists(body, arm_vertex, arm_faces, problems):
    """wrist and shoulder_to_wrist (m), each the mean of both arms."""
    girths, reaches = [], []
    for side in SIDES:
        if not arm_faces[side].any():
            problems.append(f"no {side} arm: wrist and shoulder_to_wrist cannot be taken")
            return {}
        start = shoulder_point(body, side)
        points = body.vertices[arm_vertex[side]]
        distance = np.linalg.norm(points - start, axis=1)
        length = float(distance.max())
        axis = (points[int(np.argmax(distance))] - start) / length

        def girth(offsets, side=side, start=start, axis=axis):
            return np.array([arm_girth(body, arm_faces[side], start, axis, t) for t in np.atleast_1d(offsets)])

        low, high = (f * length for f in WRIST_BAND)
        value, where = extreme_over_band(girth, low, high, False, where=True, steps=SEARCH_STEPS)
        girths.append(value)
        reaches.append(where)
    return {"wrist": float(np.mean(girths)), "shoulder_to_wrist": float(np.mean(reaches))}
