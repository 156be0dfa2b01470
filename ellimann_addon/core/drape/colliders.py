"""A mannequin's convex pieces, or its skin, as triangle meshes for a cloth solver's collision objects.

Cloth solvers (Blender's among them) collide with triangles, so each piece becomes a mesh: an
ellipsoid is the unit icosphere at ``sphere_subdivisions`` under the ellipsoid's matrix
``S @ diag(D, 1)`` (every ellipsoid shares one mesh), a cushion is :func:`cushion.cushion_mesh` at
``cushion_subdivisions`` in its first ellipsoid's frame. Vertices lie on the exact surface, so the
flat faces sit inside it by at most the chord sag of the subdivision level.

The skin (``core.skin``) is one closed mesh over the pieces: :func:`skin_collider` gives it as one collision
piece, :func:`skin_distance` the distance to it that clears a garment of it.
"""

from dataclasses import dataclass

import numpy as np

from ..constants import COLLIDER_LEVELS
from ..geometry.cushion import mannequin_cushions
from ..geometry.ellipsoid import matrix_world
from ..geometry.frames import rigid_matrix
from ..geometry.mesh import check_subdivision_level, icosphere
from ..mannequin.skin_record import SkinSettings
from ..skin.measure import SkinField
from ..skin.surface import build_skin


@dataclass
class CollisionPiece:
    """One collision mesh: ``vertices`` (V, 3) local to ``matrix`` (4x4 world matrix), ``faces`` (F, 3)."""

    name: str
    kind: str  # "ELLIPSOID", "CUSHION", "SKIN" or "MESH" (a body mesh)
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


SKIN_COLLIDER = "Skin"  # the skin collider's name (one mesh, kind "SKIN")


def skin_collider(mannequin, level):
    """(Skin, CollisionPiece): the mannequin's skin at ``level`` ("preview", "final": core.skin.settings.LEVELS)
    and the same mesh as one collision piece in world coordinates. SkinError (one line) for a skin that cannot be
    made; MannequinError for pieces without bones."""
    skin = build_skin(mannequin, SkinSettings.at_level(level))
    return skin, CollisionPiece(SKIN_COLLIDER, "SKIN", np.eye(4), skin.vertices, skin.faces)


def skin_distance(skin):
    """``distance(points (P, 3)) -> (P,)``: the signed distance to a skin's surface, from its field (exact on the
    surface, within a few per cent of the Euclidean distance in the centimetres around it, where a garment is
    cleared of it; 1 m wherever no piece is near)."""
    field = SkinField(skin.mannequin, skin.settings)
    return lambda points: field.pieces.at(np.asarray(points, float).reshape(-1, 3), field.reach)[0]
