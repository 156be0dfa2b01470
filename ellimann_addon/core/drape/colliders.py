"""A mannequin's convex pieces as triangle meshes for a cloth solver's collision objects.

Cloth solvers (Blender's among them) collide with triangles, so each piece becomes a mesh: an
ellipsoid is the unit icosphere at ``sphere_subdivisions`` under the ellipsoid's matrix
``S @ diag(D, 1)`` (every ellipsoid shares one mesh), a cushion is :func:`cushion.cushion_mesh` at
``cushion_subdivisions`` in its first ellipsoid's frame. Vertices lie on the exact surface, so the
flat faces sit inside it by at most the chord sag of the subdivision level.
"""

from dataclasses import dataclass

import numpy as np

from ..constants import COLLIDER_LEVELS
from ..geometry.cushion import mannequin_cushions
from ..geometry.ellipsoid import matrix_world
from ..geometry.frames import rigid_matrix
from ..geometry.mesh import check_subdivision_level, icosphere


@dataclass
class CollisionPiece:
    """One collision mesh: ``vertices`` (V, 3) local to ``matrix`` (4x4 world matrix), ``faces`` (F, 3)."""

    name: str
    kind: str  # "ELLIPSOID" or "CUSHION"
    matrix: np.ndarray
    vertices: np.ndarray
    faces: np.ndarray

    def world_vertices(self):
        return self.vertices @ self.matrix[:3, :3].T + self.matrix[:3, 3]


def check_subdivisions(name, value):
    """A collision mesh level (constants.COLLIDER_LEVELS) as an int, else ElliMannError naming ``name``."""
    return check_subdivision_level(name, value, COLLIDER_LEVELS)


def collision_pieces(mannequin, cushions=False, sphere_subdivisions=2, cushion_subdivisions=2):
    """The mannequin's pieces as meshes: cushions (``cushions``, one per cushion pair) and the ellipsoids
    not in a cushion, in topology order, cushions last. Names as :class:`garment_fit.BodyPieces`."""
    mannequin.check()
    sphere_subdivisions = check_subdivisions("sphere_subdivisions", sphere_subdivisions)
    cushion_subdivisions = check_subdivisions("cushion_subdivisions", cushion_subdivisions)
    topology = mannequin.topology
    sphere_vertices, sphere_faces = icosphere(sphere_subdivisions)
    frames = matrix_world(mannequin.rotation, mannequin.center, mannequin.semi_axes)
    pieces = [
        CollisionPiece(topology.names[i], "ELLIPSOID", frames[i], sphere_vertices, sphere_faces)
        for i in topology.single_parts(cushions)
    ]
    for hull in mannequin_cushions(mannequin, cushion_subdivisions, local=True) if cushions else []:
        rigid = rigid_matrix(mannequin.rotation[hull.first], mannequin.center[hull.first])
        pieces.append(CollisionPiece(hull.name, "CUSHION", rigid, hull.vertices, hull.faces))
    return pieces


def triangle_count(pieces):
    return int(sum(len(p.faces) for p in pieces))
