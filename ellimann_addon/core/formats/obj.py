"""Wavefront OBJ of a mannequin's pieces, rest or posed, written by the core with numpy alone.

One convention for every OBJ ElliMann reads or writes: metres, Y up, -Z forward, as Blender's OBJ importer and
exporter assume (a scene point (x, y, z) is the file's (x, z, -y); ``core.geometry.mesh.from_scene_axes``).
One object (``o``) per piece: ellipsoids as icospheres, cushions as their hull meshes (posed, those across a joint
in two halves, ``core.pose.posed_pieces``); faces counter-clockwise seen from outside. With a skin
(``core.skin.surface.Skin``, ``--skin``) the file holds the skin alone, one closed mesh (:func:`write_skin_obj`).
"""

import numpy as np

from ..constants import CUSHION_LEVEL, UNIT_SPHERE_LEVEL
from ..files import atomic_write_text
from ..geometry.cushion import mannequin_cushions
from ..geometry.mesh import from_scene_axes, icosphere
from ..pose.posed_pieces import PosingRig

AXES = "metres, Y up, -Z forward (Blender's OBJ axes)"


def mannequin_pieces(mannequin, pose=None, cushions=False):
    """[(name, vertices (V, 3) in ElliMann's axes, faces (F, 3))] of every piece shown: the ellipsoids (those
    in cushion pairs replaced by their cushions with ``cushions``), in ``pose`` if one is given."""
    cushion_meshes = []
    if pose is not None:
        posed_body = PosingRig(mannequin, cushions=cushions, subdivisions=CUSHION_LEVEL).pose(pose)
        shown, cushion_meshes = posed_body.mannequin, posed_body.cushions
    else:
        shown = mannequin
        if cushions:
            cushion_meshes = mannequin_cushions(mannequin, CUSHION_LEVEL)
    sphere, sphere_faces = icosphere(UNIT_SPHERE_LEVEL)
    pieces = [
        (
            shown.topology.names[i],
            np.einsum("ij,vj->vi", shown.rotation[i] * shown.semi_axes[i], sphere) + shown.center[i],
            sphere_faces,
        )
        for i in shown.topology.single_parts(cushions)
    ]
    return pieces + [(mesh.name, mesh.vertices, mesh.faces) for mesh in cushion_meshes]


def obj_text(pieces, title, smooth=False):
    """OBJ text of ``pieces`` ([(name, vertices in ElliMann's axes, faces)]), its first line ``# title (axes)``;
    ``smooth``: each object in smoothing group 1 (importers shade it smooth, as a skin is)."""
    parts = [f"# {title} ({AXES})\n"]
    start = 1
    for name, vertices, faces in pieces:
        faces = np.asarray(faces, dtype=np.int64)
        # one format string per block: a skin's 100k vertices in a fraction of a second, not seconds line by line
        parts.append(f"o {name}\n" + ("s 1\n" if smooth else ""))
        parts.append(("v %.9g %.9g %.9g\n" * len(vertices)) % tuple(from_scene_axes(vertices).ravel().tolist()))
        parts.append(("f %d %d %d\n" * len(faces)) % tuple((faces + start).ravel().tolist()))
        start += len(vertices)
    return "".join(parts)


def write_obj(mannequin, path, pose=None, cushions=False):
    """Write ``mannequin`` (in ``pose``, a core.pose.kinematics.Pose, if given) to an .obj, atomically."""
    where = f" in pose '{pose.name}'" if pose is not None else ""
    title = f"ElliMann mannequin '{mannequin.name}'{where}; measurements are the rest pose's"
    atomic_write_text(path, obj_text(mannequin_pieces(mannequin, pose, cushions), title))
    return path


def skin_title(skin, pose=None):
    """The first line of a skin's OBJ (without the axes): whose skin, how fine, which pose."""
    name = skin.mannequin.name
    where = f" in pose '{pose.name}'" if pose is not None else ""
    settings = skin.settings
    if settings.kind == "body":
        return f"ElliMann body skin of '{name}'{where}; measurements are the rest pose's"
    return (
        f"ElliMann skin of '{name}'{where}: {settings.voxel_mm:g} mm voxels, blend {settings.blend:g}; "
        "measurements are the rest pose's"
    )


def write_skin_obj(skin, path, pose=None):
    """Write ``skin`` alone (one closed mesh, named after its mannequin), in ``pose`` if given (linear-blend
    skinning, ``Skin.posed``), to an .obj, atomically."""
    vertices = skin.vertices if pose is None else skin.posed(pose)
    name = f"{skin.mannequin.name or 'mannequin'} skin"
    atomic_write_text(path, obj_text([(name, vertices, skin.faces)], skin_title(skin, pose), smooth=True))
    return path
