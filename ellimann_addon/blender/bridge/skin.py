"""The skin as a Blender object: one mesh in its mannequin's built "Skin" collection (``bridge.built``), tagged
``kind`` SKIN, that keeps what a core ``Skin`` holds besides its mesh, so that it can follow the pieces, be bound
to an armature later or be found out of date without being made again: each vertex's pieces and their weights
(integer and float point attributes), how it was made (``SkinSettings.to_dict()`` as JSON) and the matrices of the
pieces it was made from.

Rewriting a skin keeps the object and its mesh datablock (its name, materials, the user's modifiers and vertex
groups stay; only the geometry and ElliMann's own attributes and weights are replaced: a user's vertex group keeps
its name, its weights cannot outlive the surface they were painted on).
"""

import json

import bpy
import numpy as np

from ...core.errors import ElliMannError
from ...core.geometry.ellipsoid import matrix_world
from ...core.mannequin.skin_record import SkinSettings
from ...core.skin.surface import Skin
from ...core.skin.weights import INFLUENCES
from .built import built_collection, built_objects, tag_built
from .convert import fill_mesh, mesh_vertices, write_mesh_vertices

SETTINGS_KEY = "ellimann_skin"  # how the skin was made: its record (Skin.record(), BodySkin.record()) as JSON
SOURCE_KEY = "ellimann_skin_source"  # the pieces' matrices (n x 12) it was made from, for staleness
PIECE_ATTRIBUTES = tuple(f"ellimann_piece_{k}" for k in range(INFLUENCES))
WEIGHT_ATTRIBUTES = tuple(f"ellimann_piece_weight_{k}" for k in range(INFLUENCES))
STALE_TOLERANCE = 1e-5  # m: pieces moved by more are not what the skin was made from
SKIN_COLOR = (0.82, 0.72, 0.64, 1.0)
SKIN_PART_NAME = "Skin"


def skin_object(collection):
    """The skin ElliMann built for a mannequin collection, or None."""
    found = built_objects(collection, "SKIN")
    return found[0] if found else None


def piece_matrices(mannequin):
    """(n, 12): the first three rows of every piece's matrix_world (S @ diag(D, 1)), in topology order."""
    return matrix_world(mannequin.rotation, mannequin.center, mannequin.semi_axes)[:, :3, :].reshape(-1, 12)


def write_skin_object(collection, skin, name=None):
    """The skin object of ``collection`` holding ``skin`` (a core Skin, world coordinates): made in the built Skin
    collection if there is none, else its geometry replaced in place. Returns the object."""
    obj = skin_object(collection)
    if obj is None:
        name = name or f"{collection.name} Skin"
        mesh = bpy.data.meshes.new(name)
        obj = bpy.data.objects.new(name, mesh)
        tag_built(obj, "SKIN", SKIN_PART_NAME)
        obj.color = SKIN_COLOR
        built_collection(collection, "SKIN").objects.link(obj)
    elif obj.data.users > 1:  # shared with another object: this one gets its own
        obj.data = obj.data.copy()
    mesh = obj.data
    groups = [group.name for group in obj.vertex_groups]  # their names live on the mesh: kept, their weights cannot be
    mesh.clear_geometry()
    for group in groups:
        if group not in obj.vertex_groups:
            obj.vertex_groups.new(name=group)
    inverse = np.linalg.inv(np.array(obj.matrix_world))
    fill_mesh(mesh, skin.vertices @ inverse[:3, :3].T + inverse[:3, 3], skin.faces)
    mesh.shade_smooth()
    if skin.settings.kind != "body":  # the pieces each vertex follows (a live step moves it with them)
        for names, kind, values in (
            (PIECE_ATTRIBUTES, "INT", skin.pieces.astype(np.int32)),
            (WEIGHT_ATTRIBUTES, "FLOAT", skin.weights.astype(np.float32)),
        ):
            for k, name_k in enumerate(names):
                attribute = mesh.attributes.new(name_k, kind, "POINT")
                attribute.data.foreach_set("value", np.ascontiguousarray(values[:, k]))
    obj[SETTINGS_KEY] = json.dumps(skin.record())
    obj[SOURCE_KEY] = piece_matrices(skin.mannequin).ravel().tolist()
    return obj


def skin_vertices(obj):
    """The skin's mesh vertices (V, 3) in world coordinates, as it was made (before any deformation)."""
    matrix = np.array(obj.matrix_world)
    return mesh_vertices(obj.data) @ matrix[:3, :3].T + matrix[:3, 3]


def write_skin_vertices(obj, vertices):
    """Move the skin's mesh vertices to ``vertices`` (V, 3) world coordinates (same count)."""
    inverse = np.linalg.inv(np.array(obj.matrix_world))
    write_mesh_vertices(obj.data, vertices @ inverse[:3, :3].T + inverse[:3, 3])


def read_skin(obj, mannequin):
    """The core Skin a skin object holds, made from ``mannequin`` (the pieces it was made from: see
    :func:`is_stale_skin`); None if the object lacks what a skin holds (a mesh edited since, a file from elsewhere)."""
    mesh = obj.data
    names = PIECE_ATTRIBUTES + WEIGHT_ATTRIBUTES
    if obj.type != "MESH" or any(name not in mesh.attributes for name in names) or SETTINGS_KEY not in obj:
        return None
    count = len(mesh.vertices)
    columns = []
    for name, dtype in zip(names, [np.int32] * INFLUENCES + [np.float32] * INFLUENCES):
        column = np.empty(count, dtype=dtype)
        mesh.attributes[name].data.foreach_get("value", column)
        columns.append(column)
    pieces = np.stack(columns[:INFLUENCES], axis=1).astype(np.int64)
    if len(pieces) and (pieces.min() < 0 or pieces.max() >= len(mannequin.center)):
        return None
    mesh.calc_loop_triangles()
    faces = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", faces)
    weights = np.stack(columns[INFLUENCES:], axis=1).astype(float)
    settings = skin_settings_of(obj)
    if settings is None:
        return None
    return Skin(mannequin, skin_vertices(obj), faces.reshape(-1, 3).astype(np.int64), pieces, weights, settings)


def skin_settings_of(obj):
    """How a skin object was made (SkinSettings), or None if it does not say."""
    record = skin_record_of(obj)
    try:
        return None if record is None else SkinSettings.from_dict(record)
    except ElliMannError:
        return None


def skin_record_of(obj):
    """A skin object's ``skin`` section (how to make it again, core.mannequin.skin_record), or None."""
    try:
        record = json.loads(obj[SETTINGS_KEY])
    except (KeyError, ValueError, TypeError):
        return None
    return record if isinstance(record, dict) else None


def is_stale_skin(obj, mannequin):
    """True if the pieces of ``mannequin`` are not those the skin was made from (moved, or another topology)."""
    stored = obj.get(SOURCE_KEY)
    current = piece_matrices(mannequin).ravel()
    if stored is None or len(stored) != len(current):
        return True
    return not np.allclose(np.array(stored), current, atol=STALE_TOLERANCE)
