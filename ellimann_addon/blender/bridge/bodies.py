"""Mesh objects as the core's body meshes (core.fitting.body_mesh.BodyMesh) and the vertex selections Fit Ellipsoid
records (core.mannequin.traces.PartTrace)."""

import numpy as np

from ...core.fitting.body_mesh import BodyMesh, loop_fingerprint
from ...core.mannequin.traces import FitSettings, PartTrace
from .convert import mesh_vertices


def mesh_fingerprint(mesh):
    """core.fitting.body_mesh's connectivity fingerprint of a mesh's polygons (the same as of its OBJ file)."""
    corners = np.empty(len(mesh.loops), dtype=np.int64)
    mesh.loops.foreach_get("vertex_index", corners)
    starts = np.empty(len(mesh.polygons), dtype=np.int64)
    sizes = np.empty(len(mesh.polygons), dtype=np.int64)
    mesh.polygons.foreach_get("loop_start", starts)
    mesh.polygons.foreach_get("loop_total", sizes)
    return loop_fingerprint(corners, starts, sizes)


def body_mesh(obj, name=None):
    """The mesh object's data (not evaluated: no modifiers), in world space, as a BodyMesh named ``name``
    (default: the object's name)."""
    mesh = obj.data
    mesh.calc_loop_triangles()
    triangles = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int64)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    matrix = np.array(obj.matrix_world)
    vertices = mesh_vertices(mesh) @ matrix[:3, :3].T + matrix[:3, 3]
    return BodyMesh(name or obj.name, vertices, triangles.reshape(-1, 3), mesh_fingerprint(mesh))


def selection_trace(obj, method):
    """What Fit Ellipsoid records: the selected vertices of the mesh object ``obj`` (in Edit Mode, updated)
    and the builder's default fit settings, or None if none is selected."""
    mesh = obj.data
    selected = np.zeros(len(mesh.vertices), dtype=bool)
    mesh.vertices.foreach_get("select", selected)
    indices = np.nonzero(selected)[0]
    if not len(indices):
        return None
    return PartTrace(obj.name, len(mesh.vertices), mesh_fingerprint(mesh), indices, FitSettings(), method=method)
