"""A mannequin's skin: one closed, 2-manifold, consistently wound triangle mesh over its pieces, smooth where
neighbours meet (the field of ``core.skin.field``, meshed by ``core.skin.contour``), with the weights by which it
follows its pieces and bones (``core.skin.weights``).

The pieces stay the mannequin's truth for collisions and m_T; the skin is for the eye, for export and for
draping on a smooth body. Cavities the pieces enclose (a pocket between the trunk's ellipsoids) are filled: only
the outer surface is kept. A body that falls apart into several outer surfaces (a piece that touches no other)
is refused, naming the pieces of the loose part.

Pieces that do not touch are kept a gap apart (``core.skin.field.apart_pairs``) unless that makes the skin worse:
where the pieces join all round a gap (an upper arm that overlaps the ribs beside an elbow kept off them), it is a
tunnel, and the skin is made again without gaps; the one with fewer handles is kept (the first, if as many).
"""

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..errors import ElliMannError
from ..geometry.mesh import connected_labels, directed_edges, volume
from ..mannequin.skin_record import SkinSettings
from ..measure.body import measure_body_mesh
from ..pose.kinematics import bone_matrices, require_joints
from .contour import marching_cubes
from .field import FADE, blend_pairs, blend_widths, sample_field, skin_pieces
from .settings import check_skin_size
from .skinning import skinning_weights
from .weights import follow_pieces, piece_motions, piece_weights


class SkinError(ElliMannError):
    """A skin that cannot be made (a voxel too fine or too coarse, a body in several parts), in one line."""


@dataclass
class Skin:
    """The skin of ``mannequin`` (the pieces it was made from): vertices (V, 3) m, faces (F, 3) counter-clockwise
    from outside; each vertex's pieces (V, 4) and their weights (V, 4); how it was made (``settings``)."""

    mannequin: object
    vertices: np.ndarray
    faces: np.ndarray
    pieces: np.ndarray
    weights: np.ndarray
    settings: SkinSettings

    def record(self):
        """The ``skin`` section of its pieces' file: how to make it again."""
        return self.settings.to_dict()

    def bones(self):
        """(bones (V, 4), weights (V, 4)): linear-blend skinning weights on the SMPL joints, smooth across every
        joint and keeping the volume where the legs bend (``core.skin.skinning``; made once, on first use).
        ElliMannError without joints."""
        return self._bones

    @cached_property
    def _bones(self):
        return skinning_weights(self.vertices, self.faces, self.pieces, self.weights, self.mannequin)

    def following(self, moved):
        """This skin moved with its pieces to ``moved`` (the same topology, e.g. the next step of a slider),
        without a new surface: a preview until the skin is made again."""
        motions = piece_motions(self.mannequin, moved)
        vertices = follow_pieces(self.vertices, self.pieces, self.weights, motions)
        return Skin(moved, vertices, self.faces, self.pieces, self.weights, self.settings)

    def posed(self, pose):
        """The skin's vertices (V, 3) in ``pose`` (a core.pose.kinematics.Pose): linear-blend skinning with
        :meth:`bones`, as glTF and Blender's Armature modifier apply it. ElliMannError without joints."""
        matrices = bone_matrices(require_joints(self.mannequin), pose)[:, :3, :]
        bones, weights = self.bones()
        return follow_pieces(self.vertices, bones, weights, matrices)

    def measure(self, fractions=None):
        """The skin measured as any body mesh (core.measure.body): a BodyMeasurement at the mannequin's section
        heights (``fractions``, default its own)."""
        return measure_body_mesh(self.vertices, self.faces, fractions or self.mannequin.section_fractions)

    @property
    def volume(self):
        return volume(self.vertices, self.faces)


def build_skin(mannequin, settings=None):
    """The skin of ``mannequin`` (rest or posed) at ``settings`` (default: the final level). SkinError (one
    line, before any work where it can be told) for a voxel too fine for memory or too coarse for its thinnest
    piece, or a body whose outer surface falls apart."""
    settings = settings or SkinSettings()
    check_skin(mannequin, settings)
    pieces = skin_pieces(mannequin, settings.blend, settings.voxel)
    pieces, (vertices, faces, owner) = gapped_mesh(pieces, settings.voxel, mannequin.topology.names)
    arrays = (mannequin.rotation, mannequin.center, mannequin.semi_axes)
    vertex_pieces, weights = piece_weights(vertices, owner, *arrays, pieces.pairs, pieces.widths)
    return Skin(mannequin, vertices, faces, vertex_pieces, weights, settings)


def gapped_mesh(pieces, voxel, names):
    """(the PieceField meshed, its :func:`outer_mesh`): ``pieces`` with their gaps, or without them where the
    gaps make a skin that is not a sphere and without has fewer handles, or where with them the body falls apart
    (a piece held on by less than a gap); SkinError if it falls apart without them too."""
    try:
        surface = outer_mesh(pieces, voxel, names)
    except SkinError:
        if not len(pieces.apart):
            raise
        surface = None
    if len(pieces.apart) and (surface is None or _euler(surface) != 2):
        joined = pieces.without_gaps()
        try:
            again = outer_mesh(joined, voxel, names)
        except SkinError:
            if surface is None:
                raise
            return pieces, surface
        if surface is None or _euler(again) > _euler(surface):
            return joined, again
    return pieces, surface


def _euler(surface):
    """The Euler characteristic of a closed triangle mesh (every edge on two faces, as the meshing makes it):
    V - E + F with E = 3F / 2."""
    vertices, faces = surface[:2]
    return len(vertices) - len(faces) // 2


def outer_mesh(pieces, voxel, names):
    """(vertices, faces, each vertex's nearest piece) of the outer surface of ``pieces``' field (a PieceField) at
    ``voxel``; SkinError as :func:`outer_surface`."""
    values, grid, nearest = sample_field(pieces, voxel)
    vertices, faces, inner = marching_cubes(values, grid.origin, grid.spacing)
    vertices, faces, inner = outer_surface(vertices, faces, inner, nearest, names)
    return vertices, faces, nearest[inner]


def check_skin(mannequin, settings=None):
    """Refuse, before any work, a skin of ``mannequin`` at ``settings`` that :func:`build_skin` would refuse before
    its work: SkinError naming a voxel too fine for memory (and the finest that fits) or pieces too thin for it.
    Returns the estimated bytes (cheap: what the command line checks before a batch starts)."""
    settings = settings or SkinSettings()
    widths = blend_widths(mannequin.semi_axes, blend_pairs(mannequin.topology), settings.blend)
    try:
        return check_skin_size(mannequin, settings, FADE * max(widths, default=0.0) + 2.0 * settings.voxel)
    except ElliMannError as error:
        raise SkinError(str(error)) from None


def outer_surface(vertices, faces, inner, nearest, names):
    """The mesh's outer surface: cavities (components wound inwards, negative volume) dropped; SkinError if more
    than one outer component remains, naming the pieces of the smaller ones."""
    if len(faces) == 0:
        raise SkinError("skin: the pieces make no surface at this voxel")
    edges = directed_edges(faces)
    label = connected_labels(len(vertices), edges)
    face_label = label[faces[:, 0]]
    count = face_label.max() + 1
    corners = vertices[faces]
    signed = np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])) / 6.0
    volumes = np.bincount(face_label, weights=signed, minlength=count)
    outer = np.flatnonzero(volumes > 0.0)
    if len(outer) > 1:
        main = outer[np.argmax(volumes[outer])]
        loose = sorted({names[nearest[inner[v]]] for v in np.flatnonzero(np.isin(label, outer[outer != main]))})
        raise SkinError(
            f"skin: the body falls apart: {', '.join(loose[:4])}{' and more' if len(loose) > 4 else ''} "
            f"{'touches' if len(loose) == 1 else 'touch'} no other piece (the skin must be one closed surface)"
        )
    keep_faces = face_label == outer[0]
    kept = np.flatnonzero(label == outer[0])
    remap = np.full(len(vertices), -1)
    remap[kept] = np.arange(len(kept))
    return vertices[kept], remap[faces[keep_faces]], inner[kept]
