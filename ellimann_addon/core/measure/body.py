"""Measuring a body mesh (a scan, a body from another tool): the five m_T measurements and the extra ones,
with the arms found by geometry alone (no labels), and the mesh's problems said in one line each.

The arms are what a horizontal section holds beside the body: the section's segments are projected on X, the
projections joined into runs, and the run containing the mid-plane x_c (above the crotch) or the run nearest
x_c on each side (below it: the legs) is the body; runs farther out are arms. A vertex is an arm's when it
lies beyond the body's run at its height by ``ARM_MARGIN``. The armpit of a side is the lowest height above
the waist section where that side has no separate run any more. The landmarks and the measurements are those
of ``core.measure.extra`` (the same definitions on a mannequin's ellipsoids).
"""

from dataclasses import dataclass, field

import numpy as np

from ..constants import CM_PER_M, GIRTHS, SECTION_FRACTIONS
from ..geometry.mesh import (
    boundary_edges,
    connected_labels,
    convex_hull_2d,
    hull_girth,
    in_plane,
    section_segments,
)
from ..measurements import ALL_MEASUREMENTS
from .band_search import extreme_over_band
from .body_neck import body_neck
from .extra import CALF_BAND, CROTCH_FLOOR, MID_PLANE_HEIGHT, NECK_BAND, SIDES, THIGH_DROP, UPPER_ARM_FRACTION

ARM_SCAN_STEP = 0.005  # He between the sections that find the arms
ARM_MARGIN = 0.01  # m beyond the body's run before a vertex counts as an arm's
HEIGHT_RANGE_M = (0.5, 2.5)  # a standing adult or child in metres


@dataclass
class BodyMeasurement:
    """What measuring a body mesh gives: values (cm) of the measurements that could be taken, and one line per
    problem (each naming what could not be measured)."""

    values: dict = field(default_factory=dict)
    problems: list = field(default_factory=list)
    sections: dict = field(default_factory=dict)  # key: (k, 3) points where it is taken (loops, a line, a point)
    neck_tilt: float = float("nan")  # radians forward: the neck's axis the neck was measured square to

    @property
    def missing(self):
        return [key for key in ALL_MEASUREMENTS if key not in self.values]


def _inside(points, segments):
    """Whether each point lies inside the closed curve(s) made of ``segments`` (crossing number)."""
    y0, y1 = segments[None, :, 0, 1], segments[None, :, 1, 1]
    x0, x1 = segments[None, :, 0, 0], segments[None, :, 1, 0]
    py, px = points[:, None, 1], points[:, None, 0]
    straddle = (y0 > py) != (y1 > py)
    x_at = x0 + (py - y0) * (x1 - x0) / np.where(straddle, y1 - y0, 1.0)
    return (np.sum(straddle & (x_at > px), axis=1) % 2) == 1


def section_blobs(vertices, faces, z):
    """The section at height z as blobs: (segments (k, 2, 2), their triangles (k,), blob label (k,)).
    Segments sharing end points form closed loops; loops that overlap (pieces of a mannequin exported as
    separate closed meshes) form one blob."""
    segments, rows, keys = section_segments(vertices, faces, z, with_edges=True)
    if len(segments) == 0:
        return segments, rows, np.zeros(0, np.int64)
    nodes, ends = np.unique(keys, return_inverse=True)
    ends = ends.reshape(-1, 2)
    loop = connected_labels(len(nodes), ends)[ends[:, 0]]
    count = loop.max() + 1
    lo = np.array([segments[loop == i].reshape(-1, 2).min(axis=0) for i in range(count)])
    hi = np.array([segments[loop == i].reshape(-1, 2).max(axis=0) for i in range(count)])
    pairs = []
    for i in range(count):
        for j in range(i + 1, count):
            if np.all(lo[i] <= hi[j]) and np.all(lo[j] <= hi[i]):
                a, b = segments[loop == i], segments[loop == j]
                if _inside(a[:, 0], b).any() or _inside(b[:, 0], a).any():
                    pairs.append((i, j))
    blob = connected_labels(count, pairs)[loop]
    return segments, rows, blob


def _body_blobs(segments, blob, mid_x):
    """Labels of the body's blobs: the widest whose x range holds mid_x, else the nearest on each side (legs)."""
    labels = np.unique(blob)
    lo = np.array([segments[blob == b, :, 0].min() for b in labels])
    hi = np.array([segments[blob == b, :, 0].max() for b in labels])
    inside = np.nonzero((lo <= mid_x) & (hi >= mid_x))[0]
    if len(inside):
        return [labels[inside[np.argmax(hi[inside] - lo[inside])]]]
    left, right = np.nonzero(lo > mid_x)[0], np.nonzero(hi < mid_x)[0]
    nearest = [left[np.argmin(lo[left])]] if len(left) else []
    nearest += [right[np.argmax(hi[right])]] if len(right) else []
    return [labels[i] for i in nearest]


class StandingBody:
    """A closed triangle mesh of an upright body in metres (Z up), with its landmarks."""

    def __init__(self, vertices, faces, fractions=None):
        self.vertices = np.asarray(vertices, float)
        self.faces = np.asarray(faces, np.int64)
        self.fractions = dict(fractions or SECTION_FRACTIONS)
        self.bottom = float(self.vertices[:, 2].min())
        self.height = float(self.vertices[:, 2].max()) - self.bottom
        face_z = self.vertices[self.faces, 2]
        self.face_low, self.face_high = face_z.min(axis=1), face_z.max(axis=1)
        mid = self.section(self.at(MID_PLANE_HEIGHT))[0]
        self.mid_x = 0.5 * (mid[:, :, 0].min() + mid[:, :, 0].max()) if len(mid) else 0.0
        self.crotch_y = np.nan  # y of the crotch, once found

    def at(self, fraction):
        return self.bottom + fraction * self.height

    def crossed(self, z, rows=None):
        """Indices of the triangles (of ``rows``, default all) that the plane z = height crosses, in order: those
        with a vertex below it and one on or above it, section_segments' own rule (so its segments are the same,
        from a few hundred triangles instead of all)."""
        if rows is None:
            return np.nonzero((self.face_low < z) & (self.face_high >= z))[0]
        return rows[(self.face_low[rows] < z) & (self.face_high[rows] >= z)]

    def section(self, z, rows=None):
        """section_segments of the mesh (of the triangles ``rows``, default all) at height z (the triangle indices
        into ``faces``)."""
        crossed = self.crossed(z, rows)
        segments, rows = section_segments(self.vertices, self.faces[crossed], z)
        return segments, crossed[rows]

    def parted_section(self, z, rows=None):
        """(body segments, {side: arm segments}, triangle of each body segment) of the section at height z of the
        triangles ``rows`` (default all)."""
        crossed = self.crossed(z, rows)
        segments, rows, blob = section_blobs(self.vertices, self.faces[crossed], z)
        rows = crossed[rows]
        if len(segments) == 0:
            return segments, {}, rows
        body = np.isin(blob, _body_blobs(segments, blob, self.mid_x))
        arms = {}
        for label in np.unique(blob[~body]):
            part = segments[blob == label]
            side = "L" if part[:, :, 0].mean() > self.mid_x else "R"
            arms[side] = np.concatenate([arms[side], part]) if side in arms else part
        return segments[body], arms, rows[body]

    def find_arms(self):
        """(armpit height per side or None, arm vertex mask per side). The armpit is the first height above the
        waist section where a side has no separate blob any more; from there down, each section's arm is the
        blob that overlaps the arm just above it (so a thigh or the crotch beside a hand is never taken)."""
        start, stop = self.at(self.fractions["Wa"]), self.at(self.fractions["Sh"])
        step = ARM_SCAN_STEP * self.height
        heights = np.arange(self.at(CROTCH_FLOOR), stop, step)
        lateral = []  # per height: {side: [hulls of the blobs beside the body]}
        for z in heights:
            segments, _, blob = section_blobs(self.vertices, self.faces[self.crossed(z)], z)
            body = _body_blobs(segments, blob, self.mid_x) if len(segments) else []
            found = {side: [] for side in SIDES}
            for label in np.unique(blob):
                if label in body:
                    continue
                part = segments[blob == label].reshape(-1, 2)
                found["L" if part[:, 0].mean() > self.mid_x else "R"].append(convex_hull_2d(part))
            lateral.append(found)
        armpit = {}
        masks = {side: np.zeros(len(self.vertices), bool) for side in SIDES}
        for side in SIDES:
            # an arm still apart at the shoulder section's height has its armpit there
            top = next((i for i, z in enumerate(heights) if z >= start and not lateral[i][side]), len(heights))
            if top == 0 or heights[top - 1] < start or not lateral[top - 1][side]:
                armpit[side] = None  # no separate arm at the waist: against the torso
                continue
            armpit[side] = heights[top] if top < len(heights) else stop
            hull = max(lateral[top - 1][side], key=len)
            for i in range(top - 1, -1, -1):
                if i < top - 1:
                    touching = [h for h in lateral[i][side] if _overlap(h, hull, ARM_MARGIN)]
                    if not touching:
                        break
                    hull = convex_hull_2d(np.concatenate(touching))
                near = np.nonzero(np.abs(self.vertices[:, 2] - heights[i]) <= 0.5 * step)[0]
                masks[side][near[_within(self.vertices[near, :2], hull, ARM_MARGIN)]] = True
        return armpit, masks

    def crotch(self):
        """Height above the soles of the lowest point on the plane x = x_c above CROTCH_FLOOR (m), or NaN."""
        turned = np.stack([self.vertices[:, 1], self.vertices[:, 2], self.vertices[:, 0] - self.mid_x], axis=1)
        segments, _ = section_segments(turned, self.faces, 0.0)
        points = segments.reshape(-1, 2)
        points = points[points[:, 1] > self.at(CROTCH_FLOOR)]
        if not len(points):
            return np.nan
        lowest = int(np.argmin(points[:, 1]))
        self.crotch_y = float(points[lowest, 0])  # where it is, for drawing
        return float(points[lowest, 1] - self.bottom)

    def leg_girth(self, z, side, leg_rows):
        """One leg's girth at height z (below the crotch): the body blob on that side of the triangles
        ``leg_rows`` (the hands left out)."""
        segments, _, _ = self.parted_section(z, leg_rows)
        on_side = segments[(segments[:, :, 0].mean(axis=1) > self.mid_x) == (side == "L")]
        return hull_girth(on_side.reshape(-1, 2))


def _overlap(first, second, margin):
    """Whether two convex polygons overlap (or come within ``margin``): a corner of one inside the other."""
    return bool(_within(first, second, margin).any() or _within(second, first, margin).any())


def _within(points, hull, margin):
    """Points inside the convex polygon ``hull`` (counter-clockwise) grown by ``margin``."""
    if len(hull) < 3:
        return np.zeros(len(points), bool)
    edge = np.roll(hull, -1, axis=0) - hull
    normal = np.stack([edge[:, 1], -edge[:, 0]], axis=1) / np.linalg.norm(edge, axis=1, keepdims=True)
    offset = np.einsum("ij,ij->i", normal, hull)
    return np.all(points @ normal.T - offset <= margin, axis=1)


UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}  # a mesh file's length units (core.fitting.body_mesh reads them)
UP_AXES = ("y", "z")  # a mesh file's up axis
MESH_EXTENSIONS = (".obj", ".ply", ".stl")  # the body meshes core.fitting.body_mesh reads


def check_mesh(vertices, faces, up=None, unit=None):
    """What stops every measurement of a body mesh (metres, Z up), in one line (None if nothing): empty, lying,
    not a person's height, upside down. ``up`` and ``unit``: the options it was read with (core.fitting.body_mesh),
    if any, so the line names the option that fixes it (None: a mesh in a scene, turned or scaled instead)."""
    if len(vertices) == 0 or len(faces) == 0:
        return "the mesh is empty (no triangles): nothing can be measured"
    extent = np.ptp(vertices, axis=0)
    longest = int(np.argmax(extent))
    read = f"read with --up {up}, " if up else ""
    if extent[2] < 0.8 * extent[longest]:  # lying: a standing A-pose is at most 0.7 as wide as tall, a T-pose's
        # arm span is about its height (humans: 0.95-1.06), a body lying on its side is 0.6 as tall as long
        file_axis = {("y", 1): "z", ("z", 1): "y"}.get((up, longest))
        if up is None:
            fix = "turn it to stand along Z"
        else:
            fix = f"pass --up {file_axis}" if file_axis else "give the file's up axis (--up y or z)"
        return (
            f"the body lies down ({read}it is {extent[longest]:.2f} m long along {'XYZ'[longest]} and "
            f"{extent[2]:.2f} m tall): {fix}; nothing measured"
        )
    low, high = HEIGHT_RANGE_M
    if not low <= extent[2] <= high:
        given = extent[2] / UNITS.get(unit, 1.0)
        fits = [name for name, scale in UNITS.items() if low <= given * scale <= high]
        if unit is None:
            fix = "scale it to metres" if fits else "scale it to a person's size"
        else:
            fix = f"pass --unit {fits[0]}" if fits else "scale it to a person's size"
        return (
            f"the body is {given:.4g} {unit or 'units'} tall, not a person's height ({low:g} to {high:g} m): {fix}; "
            "nothing measured"
        )
    bottom, tall = vertices[:, 2].min(), extent[2]
    soles = vertices[vertices[:, 2] < bottom + 0.03 * tall]
    crown = vertices[vertices[:, 2] > bottom + 0.97 * tall]
    if np.ptp(soles[:, 0]) < np.ptp(crown[:, 0]):
        return (
            f"the body stands on its head ({read}its narrow end, the crown, is at the bottom): turn it over; "
            "nothing measured"
        )
    return None


def measure_body_mesh(vertices, faces, fractions=None, neck_tilt=None, arms=None):
    """Measure an upright A-pose body mesh (metres, Z up, facing -Y): a BodyMeasurement. ``neck_tilt``: the
    neck's forward tilt (radians) when it is known (a mannequin's own mesh or skin: its own tilt); by default
    the tilt a tape drawn tight settles at (core.measure.neck). ``arms``: {"L", "R": (V,) bool} the arms' vertices
    when they are known (a skin knows them from the pieces it follows): every section then leaves them out,
    wherever the armpit is; by default they are found by geometry (StandingBody.find_arms) and a girth above the
    armpit is not taken."""
    vertices, faces = np.asarray(vertices, float).reshape(-1, 3), np.asarray(faces, np.int64).reshape(-1, 3)
    result = BodyMeasurement()
    fatal = check_mesh(vertices, faces)
    if fatal:
        result.problems.append(fatal)
        return result
    body = StandingBody(vertices, faces, fractions)
    open_edges = boundary_edges(faces)
    values = result.values
    values["He"] = body.height
    z_sh = body.at(body.fractions["Sh"])
    segments, _ = body.section(z_sh)
    values["Sh"] = float(np.ptp(segments[:, :, 0])) if len(segments) else 0.0
    result.sections["Sh"] = _at_height(convex_hull_2d(segments.reshape(-1, 2)) if len(segments) else [], z_sh)

    if arms is None:
        armpit, arm_vertex = body.find_arms()
    else:
        arm_vertex = {side: np.asarray(arms[side], bool) for side in SIDES}
        armpit = {side: np.inf for side in SIDES}  # the arms' own faces are left out of every section instead
    arms_found = all(armpit[side] is not None and arm_vertex[side].any() for side in SIDES)
    if not arms_found:
        result.problems.append(
            ("the arms are against the torso (no gap beside the waist section)" if arms is None else "no arm given")
            + ": Br, Wa, Hi, thigh, upper_arm and arm_length cannot be taken"
        )
    arm_faces = {side: arm_vertex[side][faces].all(axis=1) for side in SIDES}
    leg_rows = np.nonzero(~(arm_vertex["L"] | arm_vertex["R"])[faces].any(axis=1))[0]
    body_rows = None if arms is None else np.nonzero(~(arm_faces["L"] | arm_faces["R"]))[0]
    lowest_armpit = min((z for z in armpit.values() if z is not None), default=np.inf)
    for key in GIRTHS:
        z = body.at(body.fractions[key])
        if not arms_found:
            continue
        if z >= lowest_armpit:
            result.problems.append(
                f"{key}: its section ({z - body.bottom:.3f} m) is above the armpit "
                f"({lowest_armpit - body.bottom:.3f} m): arms too close to the torso; not taken"
            )
            continue
        segments = body.parted_section(z)[0] if arms is None else body.section(z, body_rows)[0]
        values[key], hull = hull_girth(segments.reshape(-1, 2))
        result.sections[key] = _at_height(hull, z)

    crotch = body.crotch()
    if np.isfinite(crotch):
        values["crotch_height"] = crotch
        result.sections["crotch_height"] = np.array([[body.mid_x, body.crotch_y, body.bottom + crotch]])
        if arms_found:
            z = body.bottom + crotch - THIGH_DROP * body.height
            girths = [body.leg_girth(z, side, leg_rows) for side in SIDES]
            values["thigh"] = float(np.mean([g for g, _ in girths]))
            result.sections["thigh"] = _at_height(girths[0][1], z)
        low, high = (body.bottom + f * crotch for f in CALF_BAND)

        def calf(heights, side):
            return np.array([body.leg_girth(z, side, leg_rows)[0] for z in heights])

        found = [extreme_over_band(lambda h, s=side: calf(h, s), low, high, True, where=True) for side in SIDES]
        values["calf"] = float(np.mean([value for value, _ in found]))
        result.sections["calf"] = _at_height(body.leg_girth(found[0][1], "L", leg_rows)[1], found[0][1])
    else:
        result.problems.append(
            "no crotch (the legs are not apart at the mid-plane): crotch_height, thigh and calf cannot be taken"
        )

    values["neck"], result.neck_tilt, result.sections["neck"] = body_neck(body, neck_tilt)
    if not np.isfinite(values["neck"]):
        del values["neck"], result.sections["neck"]
        result.problems.append(
            f"no neck: the sections crossing the neck's axis between {NECK_BAND[0]:.2f} and {NECK_BAND[1]:.2f} He "
            "are empty; neck cannot be taken"
        )

    if arms_found:
        lengths, girths = [], []
        for side in SIDES:
            start, tip, length, girth, loop = arm_reading(body, side, z_sh, arm_vertex[side], arm_faces[side])
            lengths.append(length)
            girths.append(girth)
            if side == "L":
                result.sections["arm_length"], result.sections["upper_arm"] = np.array([start, tip]), loop
        values["arm_length"] = float(np.mean(lengths))
        values["upper_arm"] = float(np.mean(girths))
    if len(open_edges):
        crossed = _keys_crossing(body, open_edges, result)
        result.problems.append(
            f"the mesh is not closed ({len(open_edges)} boundary edges): "
            + (
                f"{', '.join(crossed)} cannot be taken (their sections cross a hole)"
                if crossed
                else "no section crosses a hole"
            )
        )
        for key in crossed:
            values.pop(key, None)
    result.values = {key: float(values[key]) * CM_PER_M for key in ALL_MEASUREMENTS if key in values}
    return result


def _at_height(hull, z):
    """A 2-D hull as 3-D points at height z."""
    hull = np.asarray(hull, float).reshape(-1, 2)
    return np.c_[hull, np.full(len(hull), z)]


def _shoulder_point(body, z_sh, side):
    segments, _ = body.section(z_sh)
    points = segments.reshape(-1, 2)
    i = int(np.argmax(points[:, 0] if side == "L" else -points[:, 0]))
    return np.array([points[i, 0], points[i, 1], z_sh])


def arm_reading(body, side, z_sh, arm_vertex, arm_faces):
    """(shoulder point, fingertip, shoulder-to-fingertip length m, upper-arm girth m, its loop (k, 3)) of an arm."""
    start = _shoulder_point(body, z_sh, side)
    points = body.vertices[arm_vertex]
    distance = np.linalg.norm(points - start, axis=1)
    tip = points[int(np.argmax(distance))]
    length = float(distance.max())
    axis = (tip - start) / length
    origin = start + UPPER_ARM_FRACTION * length * axis
    moved, frame = in_plane(body.vertices, origin, axis)
    segments, _, blob = section_blobs(moved, body.faces[arm_faces], 0.0)
    if len(segments) == 0:
        return start, tip, length, 0.0, np.zeros((0, 3))
    # the arm's own loop: the blob around the axis (a torso vertex near the armpit may be in the mask)
    around = [b for b in np.unique(blob) if _inside(np.zeros((1, 2)), segments[blob == b])[0]]
    if around:
        segments = segments[blob == around[0]]
    girth, hull = hull_girth(segments.reshape(-1, 2))
    return start, tip, length, girth, origin + hull @ frame[:2]


def _keys_crossing(body, open_edges, result):
    """The measurements whose section (its z range) meets the z range of a boundary edge."""
    z = body.vertices[open_edges, 2]
    lo, hi = z.min(axis=1), z.max(axis=1)
    return [
        key
        for key, points in result.sections.items()
        if len(points) and np.any((lo <= points[:, 2].max()) & (hi >= points[:, 2].min()))
    ]
