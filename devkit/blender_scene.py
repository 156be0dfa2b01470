"""Blender test helpers: select objects, look up parts, make a mesh to trace, and snapshot a file's state so
tests can assert that a refused operator changed nothing (or that undo brought everything back)."""

import bpy
import numpy as np
from mathutils import Matrix

from ellimann_addon.core.geometry.frames import rigid_matrix
from ellimann_addon.core.geometry.mesh import icosphere

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
    """Objects (transform, data, collections, parent, ElliMann fields), collections, meshes (with their vertex
    counts) and curves, armatures (each pose bone's rotation and location, the assigned action) and actions,
    and the scene's frame range and current frame."""
    objects = {}
    for obj in bpy.data.objects:
        part = obj.ellimann
        objects[obj.name] = (
            Matrix4(obj.matrix_world),
            obj.data.name if obj.data else None,
            tuple(sorted(c.name for c in obj.users_collection)),
            obj.parent.name if obj.parent else None,
            tuple(getattr(part, f) for f in PART_FIELDS),
            tuple(sorted(part.depends)),
        )
    collections = {
        c.name: (
            tuple(sorted(ch.name for ch in c.children)),
            c.ellimann.is_mannequin,
            c.ellimann.role,
            c.ellimann.has_measured,
            tuple(c.ellimann.measured),
        )
        for c in bpy.data.collections
    }
    scene = bpy.context.scene
    armatures = {
        obj.name: (
            tuple((b.name, Matrix4(b.matrix_basis)) for b in obj.pose.bones),
            obj.animation_data.action.name if obj.animation_data and obj.animation_data.action else None,
        )
        for obj in bpy.data.objects
        if obj.type == "ARMATURE"
    }
    return {
        "objects": objects,
        "collections": collections,
        "meshes": sorted((m.name, len(m.vertices)) for m in bpy.data.meshes),
        "curves": sorted(c.name for c in bpy.data.curves),
        "armatures": armatures,
        "actions": sorted(a.name for a in bpy.data.actions),
        "active_collection": bpy.context.view_layer.active_layer_collection.name,
        "frames": (scene.frame_start, scene.frame_end, scene.frame_current),
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


def reference_mesh(rotation, center, semi_axes, name="Reference"):
    """An ellipsoid-shaped user mesh (not an ElliMann part) whose object transform is not the identity."""
    unit, faces = icosphere(3)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata((unit * semi_axes).tolist(), [], faces.tolist())
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    obj.matrix_world = Matrix(rigid_matrix(rotation, center).tolist())
    return obj


def edit_with_selection(obj, selected):
    """Make ``obj`` the only selected object and enter Edit Mode with exactly the vertices ``selected`` selected."""
    select(obj)
    # Edit Mode also selects the vertices of selected edges and faces: deselect everything there first.
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="DESELECT")
    bpy.ops.object.mode_set(mode="OBJECT")
    flags = np.zeros(len(obj.data.vertices), bool)
    flags[selected] = True
    obj.data.vertices.foreach_set("select", flags)
    bpy.ops.object.mode_set(mode="EDIT")
