"""What a body skin must stay: one closed, 2-manifold, consistently wound surface of Euler characteristic 2 (the
topology's, which a deformation cannot change but a bad file can), no triangle turned over or crushed by the
correction (a fold: the cheap check of the loop), and the arms clear of the trunk at the girth sections where the
bodies' are. A full self-intersection test (every pair of triangles) is the tests' (devkit/mesh_checks.py)."""

import numpy as np

from ..constants import GIRTHS
from ..geometry.mesh import convex_hull_2d, euler_characteristic, face_normals, is_closed_manifold

MIN_AREA_SHARE = 0.05  # a triangle crushed below this share of its area before the correction is a fold
# turned triangles a correction may leave in a crease (the armpits' hold a few nearly upright ones that turn over
# when the arms come in by a centimetre or two) before the mesh counts as folded: 0.1 % of them
FOLD_ALLOWANCE = 0.001
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
