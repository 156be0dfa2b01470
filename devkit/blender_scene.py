"""Blender test helpers: select objects, look up parts, and snapshot a file's state so tests can assert
that a refused operator changed nothing."""

import bpy
import numpy as np

PART_FIELDS = ("is_part", "kind", "part_name", "side", "region", "girth", "partner")


class Matrix4:
    """An object matrix that compares equal up to single precision: Blender re-derives matrix_world from
    location, rotation and scale on every update, which moves the last bits."""

    def __init__(self, matrix):
        self.values = np.array(matrix, dtype=float)

    def __eq__(self, other):
        return isinstance(other, Matrix4) and np.allclose(self.values, other.values, rtol=1e-6, atol=1e-7)

    def __repr__(self):
        return f"Matrix4({self.values.round(6).tolist()})"


def state():
    """Objects (transform, data, collections, parent, ElliMann fields), collections, meshes and curves."""
    objects = {}
    for obj in bpy.data.objects:
        part = obj.ellimann
        objects[obj.name] = (
            Matrix4(obj.matrix_world), obj.data.name if obj.data else None,
            tuple(sorted(c.name for c in obj.users_collection)), obj.parent.name if obj.parent else None,
            tuple(getattr(part, f) for f in PART_FIELDS), tuple(sorted(part.depends)),
        )
    collections = {
        c.name: (tuple(sorted(ch.name for ch in c.children)), c.ellimann.is_mannequin, c.ellimann.role,
                 c.ellimann.has_measured, tuple(c.ellimann.measured))
        for c in bpy.data.collections
    }
    return {
        "objects": objects,
        "collections": collections,
        "meshes": sorted(m.name for m in bpy.data.meshes),
        "curves": sorted(c.name for c in bpy.data.curves),
        "active_collection": bpy.context.view_layer.active_layer_collection.name,
    }


def parts(collection):
    """{part name: object} of a mannequin collection's ellipsoids."""
    return {o.ellimann.part_name: o for o in collection.objects if o.ellimann.kind == "ELLIPSOID"}


def select(*objects, active=None):
    """Select exactly ``objects``; ``active`` (default the first) becomes the active object."""
    for obj in bpy.context.view_layer.objects:
        obj.select_set(False)
    for obj in objects:
        obj.select_set(True)
    if objects or active is not None:
        bpy.context.view_layer.objects.active = active or objects[0]
