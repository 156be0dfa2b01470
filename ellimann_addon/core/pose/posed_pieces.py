"""Posing a whole mannequin, cushions included, fast enough to follow a dragged bone.

:class:`PosingRig` is built once from a rest mannequin with joints: each part's bone, and the cushion meshes at
rest. A cushion whose two parts ride on the same bone moves rigidly with it (the hull of two moved ellipsoids
is the moved hull). A cushion that crosses a joint (Upper Arm/Forearm at the elbow, Hand/Fingers, Foot/Toes,
Oblique/Hip) is cut at rest by the plane through that joint perpendicular to the line between its two parts'
centres; each half is convex and rides on its own part's bone. At rest the halves are exactly the cushion; bent,
they only overlap on the inside of the joint (a little volume counted twice) and open on the outside, instead
of the hull of the bent pieces webbing across the inside. ``PosingRig.pose`` is forward kinematics plus one
rigid transform of every piece and cushion vertex: no hull is recomputed.

:func:`union_volume` estimates the volume of the union of posed pieces by Monte Carlo with a fixed seed (the
check that posing keeps the rest volume).
"""

from typing import NamedTuple

import numpy as np

from ..constants import CUSHION_LEVEL
from ..geometry.cushion import cushion_name, mannequin_cushions
from ..geometry.mesh import face_normals
from ..mannequin.skeleton import cross_joint_pairs, part_bones
from .kinematics import forward_kinematics, require_joints


class PosedMesh(NamedTuple):
    """A convex mesh piece: name, the bone (joint index) it rides on, vertices (V, 3) world, faces (F, 3)."""

    name: str
    bone: int
    vertices: np.ndarray
    faces: np.ndarray


class PosedBody(NamedTuple):
    """A posed mannequin (its ellipsoids moved rigidly, joints posed) and its cushion meshes, posed."""

    mannequin: object
    cushions: list


def clip_convex_mesh(vertices, faces, point, normal, sources=False):
    """The part of a closed convex mesh on the side (x - point) . normal <= 0, closed by a flat cap:
    (vertices, faces) wound outward, or None if nothing of it lies on that side. The whole mesh if it lies
    entirely on that side.

    ``sources=True`` adds where each vertex comes from, (first (V,), second (V,), share (V,)): the vertex is
    (1 - share) vertices[first] + share vertices[second] (an own vertex: first = second, share 0; a cut point: the
    edge it cuts), and first = second = -1 for the cap's centre, the mean of the cut points (:func:`clipped_vertices`
    moves the part with its mesh)."""
    vertices = np.asarray(vertices, dtype=float)
    normal = np.asarray(normal, dtype=float) / np.linalg.norm(normal)
    side = (vertices - point) @ normal
    inside = side <= 0.0
    own = np.arange(len(vertices))
    if not inside.any():
        return None
    if inside.all():
        return (vertices, np.asarray(faces)) + ((own, own, np.zeros(len(own))),) * sources
    keep = faces[inside[faces].all(axis=1)]
    new_points, crossing, edges = [], {}, []

    def cut(a, b):  # the point where edge a-b (a inside, b outside) meets the plane, shared by both faces
        key = (a, b) if a < b else (b, a)
        if key not in crossing:
            t = side[a] / (side[a] - side[b])
            crossing[key] = len(vertices) + len(new_points)
            new_points.append(vertices[a] + t * (vertices[b] - vertices[a]))
            edges.append((a, b, t))
        return crossing[key]

    clipped = []
    for face in faces[inside[faces].any(axis=1) & ~inside[faces].all(axis=1)].tolist():
        polygon = []
        for k in range(3):  # Sutherland-Hodgman on one triangle, corners in order
            a, b = face[k], face[(k + 1) % 3]
            if inside[a]:
                polygon.append(a)
            if inside[a] != inside[b]:
                polygon.append(cut(a, b) if inside[a] else cut(b, a))
        clipped += [(polygon[0], polygon[k], polygon[k + 1]) for k in range(1, len(polygon) - 1)]
    points = np.concatenate([vertices, np.array(new_points)])
    # The cap: the cut points in angular order about their centroid, fanned, facing +normal (outward).
    ring = np.array(sorted(crossing.values()))
    centroid = points[ring].mean(axis=0)
    e1 = np.cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    rel = points[ring] - centroid
    ring = ring[np.argsort(np.arctan2(rel @ e2, rel @ e1), kind="stable")]
    centre_index = len(points)
    points = np.concatenate([points, centroid[None]])
    cap = np.column_stack([np.full(len(ring), centre_index), ring, np.roll(ring, -1)])
    all_faces = np.concatenate([keep, np.array(clipped, dtype=int).reshape(-1, 3), cap])
    used, remapped = np.unique(all_faces, return_inverse=True)
    if not sources:
        return points[used], remapped.reshape(-1, 3)
    cut_first, cut_second, cut_share = (np.array(column) for column in zip(*edges))
    first, second = (np.concatenate([own, column, [-1]]) for column in (cut_first, cut_second))
    share = np.concatenate([np.zeros(len(own)), cut_share, [0.0]])
    return points[used], remapped.reshape(-1, 3), (first[used], second[used], share[used])


def clipped_vertices(vertices, sources):
    """The vertices of a part :func:`clip_convex_mesh` made (with its ``sources``) after the mesh it was cut from
    moved to ``vertices`` (same order): each cut point stays at its share of its edge, the cap's centre at the cut
    points' mean. (The cut no longer lies on the plane it was made on: a preview until the part is cut again.)"""
    first, second, share = sources
    vertices = np.asarray(vertices, dtype=float)
    out = vertices[first] + share[:, None] * (vertices[second] - vertices[first])
    centre, cut = first < 0, first != second
    if centre.any():
        out[centre] = out[cut & ~centre].mean(axis=0)
    return out


class PosingRig:
    """A rest mannequin prepared for posing (see the module docstring). ``cushions`` False poses the ellipsoids
    only; ``subdivisions`` is the cushion meshes' icosphere level."""

    def __init__(self, mannequin, cushions=True, subdivisions=CUSHION_LEVEL):
        self.mannequin = mannequin
        self.joints = require_joints(mannequin)
        topology = mannequin.topology
        self.bones = part_bones(topology)
        crossing = {(i, j): joint for i, j, joint in cross_joint_pairs(topology)}
        meshes = []
        for hull in mannequin_cushions(mannequin, subdivisions) if cushions else []:
            joint = crossing.get((hull.first, hull.second))
            if joint is None:
                meshes.append(PosedMesh(hull.name, int(self.bones[hull.first]), hull.vertices, hull.faces))
                continue
            toward = mannequin.center[hull.second] - mannequin.center[hull.first]
            for part, normal in ((hull.first, toward), (hull.second, -toward)):
                half = clip_convex_mesh(hull.vertices, hull.faces, self.joints[joint], normal)
                if half is not None:
                    meshes.append(PosedMesh(half_name(hull.name, topology.names[part]), int(self.bones[part]), *half))
        self.meshes = meshes
        self._vertex_bones = (
            np.concatenate([np.full(len(m.vertices), m.bone) for m in meshes]) if meshes else np.zeros(0, dtype=int)
        )
        self._rest_vertices = np.concatenate([m.vertices for m in meshes]) if meshes else np.zeros((0, 3))
        self._splits = np.cumsum([len(m.vertices) for m in meshes])[:-1]

    def pose(self, pose):
        """The mannequin and its cushions in ``pose`` (a :class:`core.pose.kinematics.Pose`): a :class:`PosedBody`."""
        world, offset, posed = forward_kinematics(self.joints, pose.rotations, pose.translation)
        m = self.mannequin
        rotation = world[self.bones] @ m.rotation
        center = np.einsum("nij,nj->ni", world[self.bones], m.center) + offset[self.bones]
        b = self._vertex_bones
        vertices = np.einsum("vij,vj->vi", world[b], self._rest_vertices) + offset[b]
        meshes = [mesh._replace(vertices=v) for mesh, v in zip(self.meshes, np.split(vertices, self._splits))]
        return PosedBody(m.copy(rotation=rotation, center=center, joints=posed), meshes)


def half_name(cushion, part):
    """Name of the half of ``cushion`` (a cushion_name) that rides with ``part``: 'A + B (A)'."""
    return f"{cushion} ({part})"


def split_cushion_names(topology):
    """{cushion name: (half name, half name)} of the cushions a PosingRig splits at a joint."""
    return {
        cushion_name(topology.names[i], topology.names[j]): (
            half_name(cushion_name(topology.names[i], topology.names[j]), topology.names[i]),
            half_name(cushion_name(topology.names[i], topology.names[j]), topology.names[j]),
        )
        for i, j, _ in cross_joint_pairs(topology)
    }


# ------------------------------------------------------------------------------------------------ volume


def _inside_ellipsoids(points, rotation, center, semi_axes):
    local = np.einsum("nji,pnj->pni", rotation, points[:, None, :] - center[None]) / semi_axes[None]
    return np.any(np.sum(local * local, axis=-1) <= 1.0, axis=1)


def _inside_mesh(points, vertices, faces):
    normals = face_normals(vertices, faces)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True) + 1e-300
    offsets = np.einsum("ij,ij->i", normals, vertices[faces[:, 0]])
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    near = np.all((points >= low) & (points <= high), axis=1)
    out = np.zeros(len(points), dtype=bool)
    if near.any():
        out[near] = np.all(points[near] @ normals.T <= offsets, axis=1)
    return out


def pieces_contain(ellipsoids, meshes, points):
    """(P,) bool: which points lie in the union of ellipsoids (rotation, center, semi_axes arrays, or None)
    and convex meshes (a list of (vertices, faces))."""
    points = np.asarray(points, dtype=float)
    inside = np.zeros(len(points), dtype=bool)
    if ellipsoids is not None and len(ellipsoids[0]):
        inside |= _inside_ellipsoids(points, *ellipsoids)
    for vertices, faces in meshes:
        rest = ~inside
        inside[rest] |= _inside_mesh(points[rest], vertices, faces)
    return inside


def body_pieces(body):
    """The pieces of a :class:`PosedBody` as (ellipsoids, meshes) for :func:`pieces_contain`: the ellipsoids in
    no cushion (all of them if it has no cushions) and the cushion meshes."""
    m = body.mannequin
    single = m.topology.single_parts(cushions=bool(body.cushions))
    return (m.rotation[single], m.center[single], m.semi_axes[single]), [(c.vertices, c.faces) for c in body.cushions]


def union_volume(ellipsoids, meshes, samples=400_000, seed=0, chunk=50_000):
    """Monte Carlo volume (m^3) of the union of ellipsoids (rotation, center, semi_axes arrays, or None) and
    convex meshes (a list of (vertices, faces)), with its standard error: (volume, error). Uniform samples in
    the union's bounding box from a fixed seed."""
    boxes = [(v.min(axis=0), v.max(axis=0)) for v, _ in meshes]
    if ellipsoids is not None and len(ellipsoids[0]):
        from ..geometry.ellipsoid import bounds

        low, high = bounds(*ellipsoids)
        boxes.append((low.min(axis=0), high.max(axis=0)))
    low = np.min([b[0] for b in boxes], axis=0)
    high = np.max([b[1] for b in boxes], axis=0)
    rng = np.random.default_rng(seed)
    hits = 0
    for start in range(0, samples, chunk):
        points = low + rng.random((min(chunk, samples - start), 3)) * (high - low)
        hits += int(pieces_contain(ellipsoids, meshes, points).sum())
    box = float(np.prod(high - low))
    share = hits / samples
    return box * share, box * np.sqrt(share * (1.0 - share) / samples)


def body_volume(body, samples=400_000, seed=0):
    """:func:`union_volume` of a :class:`PosedBody` (its pieces that are not in cushions, and its cushions)."""
    return union_volume(*body_pieces(body), samples, seed)
