"""What a body skin must stay: one closed, 2-manifold, consistently wound surface of Euler characteristic 2 (the
topology's, which a deformation cannot change but a bad file can), no triangle turned over or crushed by the
correction (a fold: the cheap check of the loop), and the arms clear of the trunk at the girth sections where the
bodies' are. A full self-intersection test (every pair of triangles) is the tests' (devkit/mesh_checks.py)."""

import numpy as np

from ..constants import GIRTHS
from ..geometry.mesh import convex_hull_2d, euler_characteristic, face_normals, is_closed_manifold, section_segments

MIN_AREA_SHARE = 0.05  # a triangle crushed below this share of its area before the correction is a fold
# turned triangles a correction may leave in a crease (the armpits' hold a few nearly upright ones that turn over
# when the arms come in by a centimetre or two) before the mesh counts as folded: 0.1 % of them
FOLD_ALLOWANCE = 0.001
INTRUSION_FRACTIONS = tuple(np.round(np.arange(0.42, 0.781, 0.015), 3))  # He: hands to armpits, every 2.5 cm
CLEARANCE_BAND = 0.004  # m: the vertices this near a girth's height stand for its section


def surface_problems(vertices, faces):
    """One line per broken invariant of a closed body surface (empty: none)."""
    problems = []
    if not is_closed_manifold(faces):
        problems.append("not closed, 2-manifold and consistently wound")
    euler = euler_characteristic(vertices, faces)
    if euler != 2:
        problems.append(f"Euler characteristic {euler}, not 2 (a sphere's)")
    return problems


def fold_problems(before, after, faces, allowance=0.0):
    """One line per kind of fold the deformation ``before`` -> ``after`` made: triangles turned over (their
    normal turned by more than a right angle) or crushed (below MIN_AREA_SHARE of their area), when more than
    ``allowance`` (a share of the triangles) are."""
    old, new = face_normals(before, faces), face_normals(after, faces)
    turned = np.einsum("ij,ij->i", old, new) <= 0.0
    old_area, new_area = np.linalg.norm(old, axis=1), np.linalg.norm(new, axis=1)
    crushed = new_area < MIN_AREA_SHARE * old_area
    problems = []
    for what, bad in (("turned over", turned), ("crushed", crushed & ~turned)):
        if bad.sum() > allowance * len(faces):
            z = after[faces[bad]].mean(axis=1)[:, 2]
            problems.append(f"{int(bad.sum())} triangles {what} between z = {z.min():.3f} and {z.max():.3f} m")
    return problems


def arm_clearance(vertices, arms, fractions):
    """{key: bool} per girth section: whether no arm vertex near its height lies inside the hull of the trunk's
    vertices there (the arms hang clear of the trunk)."""
    bottom = vertices[:, 2].min()
    height = np.ptp(vertices[:, 2])
    arm = arms["L"] | arms["R"]
    out = {}
    for key in GIRTHS:
        z = bottom + fractions[key] * height
        near = np.abs(vertices[:, 2] - z) <= CLEARANCE_BAND
        trunk, limb = vertices[near & ~arm, :2], vertices[near & arm, :2]
        if len(trunk) < 3 or not len(limb):
            out[key] = True
            continue
        hull = convex_hull_2d(trunk)
        edge = np.roll(hull, -1, axis=0) - hull
        normal = np.stack([edge[:, 1], -edge[:, 0]], axis=1)
        inside = np.all(np.einsum("pkj,kj->pk", limb[:, None, :] - hull[None], normal) <= 0.0, axis=1)
        out[key] = not inside.any()
    return out


def principal_stretches(before, after, faces):
    """(smallest, largest) (F,) of each triangle's two principal stretches from ``before`` to ``after``: the
    square roots of the eigenvalues of G0^-1 G1 (the triangle's edge metrics), 1 for a rigid motion."""
    a, b = (
        np.stack([v[faces[:, 1]] - v[faces[:, 0]], v[faces[:, 2]] - v[faces[:, 0]]], axis=2) for v in (before, after)
    )
    g0, g1 = np.einsum("fki,fkj->fij", a, a), np.einsum("fki,fkj->fij", b, b)
    det0 = g0[:, 0, 0] * g0[:, 1, 1] - g0[:, 0, 1] * g0[:, 1, 0]
    # tr(G0^-1 G1) and det(G0^-1 G1) in closed form
    trace = (g0[:, 1, 1] * g1[:, 0, 0] - 2.0 * g0[:, 0, 1] * g1[:, 0, 1] + g0[:, 0, 0] * g1[:, 1, 1]) / det0
    det = (g1[:, 0, 0] * g1[:, 1, 1] - g1[:, 0, 1] * g1[:, 1, 0]) / det0
    spread = np.sqrt(np.maximum(0.25 * trace * trace - det, 0.0))
    return np.sqrt(np.maximum(0.5 * trace - spread, 0.0)), np.sqrt(0.5 * trace + spread)


def inside_loops(points, segments):
    """Whether each 2-D point lies inside the closed loops made of ``segments`` (k, 2, 2) (crossing number)."""
    y0, y1 = segments[None, :, 0, 1], segments[None, :, 1, 1]
    x0, x1 = segments[None, :, 0, 0], segments[None, :, 1, 0]
    py, px = points[:, None, 1], points[:, None, 0]
    straddle = (y0 > py) != (y1 > py)
    x_at = x0 + (py - y0) * (x1 - x0) / np.where(straddle, y1 - y0, 1.0)
    return (np.sum(straddle & (x_at > px), axis=1) % 2) == 1


def _segment_distance(points, segments):
    """(P,) the distance of each 2-D point to the nearest of ``segments`` (k, 2, 2)."""
    a, b = segments[None, :, 0], segments[None, :, 1]
    edge = b - a
    t = np.clip(np.einsum("pkj,pkj->pk", points[:, None] - a, edge) / np.maximum((edge * edge).sum(-1), 1e-30), 0, 1)
    nearest = a + t[..., None] * edge
    return np.sqrt(((points[:, None] - nearest) ** 2).sum(-1)).min(axis=1)


def arm_intrusion(vertices, faces, arms, fractions=INTRUSION_FRACTIONS):
    """(depth m, fraction of He) of the deepest point of an arm's horizontal section inside the trunk's (the
    triangles with no arm vertex) at heights ``fractions`` of He: 0 where the arms hang clear (the bodies')."""
    arm = arms["L"] | arms["R"]
    bottom, height = float(vertices[:, 2].min()), float(np.ptp(vertices[:, 2]))
    lowest, highest = bottom + min(fractions) * height, bottom + max(fractions) * height
    face_z = vertices[faces, 2]
    low, high = face_z.min(axis=1), face_z.max(axis=1)
    band = (high >= lowest) & (low < highest)
    trunk_faces, arm_faces = (faces[band & rows] for rows in (~arm[faces].any(axis=1), arm[faces].all(axis=1)))
    ranges = [(vertices[chosen, 2].min(axis=1), vertices[chosen, 2].max(axis=1)) for chosen in (trunk_faces, arm_faces)]
    deepest, where = 0.0, float("nan")
    for fraction in fractions:
        z = bottom + fraction * height
        trunk, limb = (
            section_segments(vertices, chosen[(low < z) & (high >= z)], z)[0]
            for chosen, (low, high) in zip((trunk_faces, arm_faces), ranges)
        )
        if not len(trunk) or not len(limb):
            continue
        points = limb[:, 0]
        inside = inside_loops(points, trunk)
        if inside.any():
            depth = float(_segment_distance(points[inside], trunk).max())
            if depth > deepest:
                deepest, where = depth, float(fraction)
    return deepest, where
