"""Mannequin <-> Blender collection. The only place where objects and core arrays meet.

An ellipsoid is an object using one shared unit-sphere mesh with ``matrix_world = S @ diag(D, 1)``;
its topology fields live in ``Object.ellimann`` (and what it was traced from, ``trace``: core.mannequin.traces's JSON).
A mannequin is a collection holding those objects, with ``Collection.ellimann`` (role, target and measured
values, rest joints when it has a skeleton).
"""

import json

import bpy
import numpy as np
from mathutils import Matrix

from ...core.constants import FEMALE_SET, UNIT_SPHERE_LEVEL
from ...core.errors import FrameError, MannequinError, Problem
from ...core.geometry.ellipsoid import decompose_matrices_world, decompose_matrix_world, matrix_world
from ...core.geometry.mesh import icosphere
from ...core.mannequin.model import Mannequin
from ...core.mannequin.topology import NAME_PATTERN, Part, Topology
from ...core.mannequin.traces import PartTrace
from ...core.measurements import MEASUREMENTS

UNIT_SPHERE_NAME = "ElliMann Unit Sphere"
UNIT_SPHERE_TOLERANCE = 1e-4  # single-precision vertices of the icosphere are within 1e-7
RIG_KEY = "ellimann_rig"  # ID property on a mannequin's armature object (services.rig builds it)
SIDE_COLORS = {"L": (0.85, 0.55, 0.45, 1.0), "R": (0.45, 0.6, 0.85, 1.0), "C": (0.8, 0.78, 0.72, 1.0)}


def unit_sphere_mesh():
    """The shared unit-sphere mesh, created once per file (a user's mesh of that name is left alone).

    A tagged mesh whose vertices were moved (Apply Scale on its only user) is not reused.
    """
    mesh = bpy.data.meshes.get(UNIT_SPHERE_NAME)
    candidates = [mesh] if mesh is not None else []
    candidates += [m for m in bpy.data.meshes if m != mesh]
    for mesh in candidates:
        if mesh.get("ellimann_unit_sphere") and is_unit_sphere(mesh):
            return mesh
    mesh = mesh_from_arrays(UNIT_SPHERE_NAME, *icosphere(UNIT_SPHERE_LEVEL))
    mesh.shade_smooth()
    mesh["ellimann_unit_sphere"] = 1
    return mesh


def mesh_from_arrays(name, vertices, faces):
    """A new triangle mesh from numpy arrays (V, 3) and (F, 3), written with foreach_set."""
    return fill_mesh(bpy.data.meshes.new(name), vertices, faces)


def fill_mesh(mesh, vertices, faces):
    """Give an empty mesh (new, or after ``clear_geometry``) the triangles of numpy arrays (V, 3) and (F, 3)."""
    vertices = np.ascontiguousarray(vertices, dtype=np.float32).reshape(-1, 3)
    faces = np.ascontiguousarray(faces, dtype=np.int32).reshape(-1, 3)
    mesh.vertices.add(len(vertices))
    mesh.vertices.foreach_set("co", vertices.ravel())
    mesh.loops.add(faces.size)
    mesh.loops.foreach_set("vertex_index", faces.ravel())
    mesh.polygons.add(len(faces))
    mesh.polygons.foreach_set("loop_start", np.arange(0, faces.size, 3, dtype=np.int32))
    mesh.update(calc_edges=True)
    return mesh


def mesh_vertices(mesh):
    """Vertex coordinates (V, 3) of a mesh in its object's local space."""
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3).astype(float)


def write_mesh_vertices(mesh, vertices):
    """Move a mesh's vertices to ``vertices`` (V, 3), local space, same count: through its ``position`` attribute
    (about 30x faster than ``vertices.foreach_set("co")``, which live updates would spend most of their time in)."""
    mesh.attributes["position"].data.foreach_set("vector", np.ascontiguousarray(vertices, dtype=np.float32).ravel())
    mesh.update()


def world_triangles(obj):
    """(vertices (V, 3) in world space, triangles (T, 3)) of a mesh object."""
    mesh = obj.data
    mesh.calc_loop_triangles()
    triangles = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    matrix = np.array(obj.matrix_world)
    return mesh_vertices(mesh) @ matrix[:3, :3].T + matrix[:3, 3], triangles.reshape(-1, 3)


def is_unit_sphere(mesh):
    """True if every vertex lies on the unit sphere (False once a scale or rotation was applied to it)."""
    if mesh is None or len(mesh.vertices) < 4:
        return False
    radius = np.linalg.norm(mesh_vertices(mesh), axis=1)
    return bool(np.all(np.abs(radius - 1.0) < UNIT_SPHERE_TOLERANCE))


def ellipsoid_frame(obj, checked=None):
    """(rotation, center, semi_axes) of an ellipsoid object; FrameError if its matrix or mesh is not one.

    A mesh that is no longer the unit sphere (Apply Scale) would otherwise be read as a sphere of
    radius 1, so it is refused here rather than silently used. ``checked`` (a dict) caches the mesh
    check across the many objects that share one mesh.
    """
    checked = {} if checked is None else checked
    if obj.type == "MESH" and obj.data.as_pointer() not in checked:
        checked[obj.data.as_pointer()] = is_unit_sphere(obj.data)
    if obj.type != "MESH" or not checked[obj.data.as_pointer()]:
        raise FrameError(
            "mesh", "is not a unit sphere: a scale or rotation was applied to the mesh (Fix Frames restores it)", "mesh"
        )
    return decompose_matrix_world(np.array(obj.matrix_world))


def read_frames(objects):
    """Stacked (rotation, center, semi_axes) of ellipsoid objects; MannequinError names every bad one."""
    objects = list(objects)
    checked = {}
    if objects and all(obj.type == "MESH" for obj in objects):
        for mesh in {obj.data.as_pointer(): obj.data for obj in objects}.values():
            checked[mesh.as_pointer()] = is_unit_sphere(mesh)
        if all(checked.values()):
            frames = decompose_matrices_world([np.array(obj.matrix_world) for obj in objects])
            if frames is not None:  # all valid: one vectorised pass (a panel's live update reads every frame)
                return frames
    problems, frames = [], []
    for obj in objects:
        try:
            frames.append(ellipsoid_frame(obj, checked))
        except FrameError as error:
            problems.append(Problem(obj.ellimann.part_name or obj.name, error.field, f"{error} (object '{obj.name}')"))
    if problems:
        raise MannequinError(problems)
    if not frames:
        return np.zeros((0, 3, 3)), np.zeros((0, 3)), np.zeros((0, 3))
    return tuple(np.array(a) for a in zip(*frames))


def write_frames(objects, rotation, center, semi_axes):
    """Set each object's matrix_world to S @ diag(D, 1)."""
    for obj, matrix in zip(objects, matrix_world(rotation, center, semi_axes)):
        obj.matrix_world = Matrix(matrix.tolist())


def is_ellipsoid(obj):
    return obj.type == "MESH" and obj.ellimann.is_part and obj.ellimann.kind == "ELLIPSOID"


def ellipsoid_objects(collection):
    """The collection's ellipsoid objects (not those of child collections), in a stable order."""
    return sorted((o for o in collection.objects if is_ellipsoid(o)), key=lambda o: natural_key(o.ellimann.part_name))


def natural_key(name):
    """Sort '2.a X' before '10.a X', then letter, label and side."""
    match = NAME_PATTERN.match(name)
    if not match:
        return (float("inf"), name)
    return (int(match.group("number")), match.group("letter"), match.group("label"), match.group("side") or "")


def new_collection(name, parent=None):
    """A new collection (never an existing one: Blender gives it a unique name) linked under ``parent``."""
    collection = bpy.data.collections.new(name)
    (parent or bpy.context.scene.collection).children.link(collection)
    return collection


def write_part(obj, part):
    props = obj.ellimann
    props.is_part = True
    props.kind = "ELLIPSOID"
    props.part_name = part.name
    props.side = part.side
    props.region = part.region
    props.girth = part.girth
    props.depends = set(part.depends)
    props.partner = part.partner


def read_part(obj):
    props = obj.ellimann
    depends = tuple(m for m in MEASUREMENTS if m in props.depends)
    return Part(props.part_name, props.side, props.region, props.girth, depends, props.partner)


def write_collection_props(collection, mannequin):
    props = collection.ellimann
    props.is_mannequin = True
    props.role = mannequin.role
    target = mannequin.measurements or {}
    # A collection holds all five target measurements or none: a partial target (a hand-written JSON may
    # give only some; the core allows it) is not kept rather than filled in.
    props.has_target = all(m in target for m in MEASUREMENTS)
    if props.has_target:
        props.target = [float(target[m]) for m in MEASUREMENTS]
    props.reference_set = mannequin.reference_set
    props.section_fractions = json.dumps(mannequin.section_fractions)
    props.has_joints = mannequin.joints is not None
    if props.has_joints:
        props.joints = np.asarray(mannequin.joints, dtype=float).tolist()


def read_landmarks(props):
    """{reference_set, section_fractions} of a mannequin collection (empty fields: the female set's)."""
    try:
        fractions = json.loads(props.section_fractions) if props.section_fractions else None
    except ValueError:
        fractions = props.section_fractions  # not JSON: Mannequin.check names the field
    return {"reference_set": props.reference_set or FEMALE_SET, "section_fractions": fractions}


def new_ellipsoid_object(part, rotation, center, semi_axes, collection, mesh=None):
    obj = bpy.data.objects.new(part.name, mesh or unit_sphere_mesh())
    write_part(obj, part)
    obj.matrix_world = Matrix(matrix_world(rotation, center, semi_axes).tolist())
    obj.color = SIDE_COLORS[part.side]
    collection.objects.link(obj)
    return obj


def write_trace(obj, trace):
    """Record on the part what it was traced from (a core.mannequin.traces.PartTrace, or None to clear it)."""
    obj.ellimann.trace = "" if trace is None else json.dumps(trace.to_dict())


def read_trace(obj):
    """The part's recorded trace (core.mannequin.traces.PartTrace) or None; MannequinError naming the part if
    unreadable."""
    text = obj.ellimann.trace
    if not text:
        return None
    name = obj.ellimann.part_name or obj.name
    try:
        data = json.loads(text)
    except ValueError:
        raise MannequinError([Problem(name, "trace", "is not valid JSON; fit the part again")]) from None
    return PartTrace.from_dict(data, name)


def mannequin_to_collection(mannequin, name=None, parent=None):
    """Build a new collection with one ellipsoid object per part. Nothing existing is touched."""
    collection = new_collection(name or mannequin.name or "Mannequin", parent)
    write_collection_props(collection, mannequin)
    mesh = unit_sphere_mesh()
    traces = mannequin.traces or {}
    for i, part in enumerate(mannequin.topology):
        obj = new_ellipsoid_object(
            part, mannequin.rotation[i], mannequin.center[i], mannequin.semi_axes[i], collection, mesh
        )
        write_trace(obj, traces.get(part.name))
    return collection


def collection_to_mannequin(collection, check=True):
    """Read a mannequin collection back into the core. Raises MannequinError naming every problem."""
    objects = ellipsoid_objects(collection)
    if not objects:
        raise MannequinError([Problem("", "collection", f"'{collection.name}' holds no ElliMann ellipsoids")])
    rotation, center, semi_axes = read_frames(objects)
    topology = Topology([read_part(obj) for obj in objects])
    props = collection.ellimann
    measurements = dict(zip(MEASUREMENTS, map(float, props.target))) if props.has_target else None
    traces = {obj.ellimann.part_name: trace for obj in objects if (trace := read_trace(obj)) is not None}
    mannequin = Mannequin(
        topology,
        rotation,
        center,
        semi_axes,
        name=collection.name,
        role=props.role,
        measurements=measurements,
        traces=traces or None,
        joints=read_joints(collection),
        **read_landmarks(props),
    )
    return mannequin.check() if check else mannequin


def rig_object(collection):
    """The armature ElliMann built for a mannequin collection, or None."""
    if collection is None:
        return None
    return next((o for o in collection.objects if o.type == "ARMATURE" and o.get(RIG_KEY)), None)


def read_joints(collection):
    """The collection's rest joints (24, 3), world space, or None if it has none."""
    props = collection.ellimann
    return np.array(props.joints, dtype=float).reshape(-1, 3) if props.has_joints else None


def update_collection_geometry(collection, mannequin):
    """Move the collection's ellipsoids to ``mannequin``'s geometry (same parts), e.g. for live updates."""
    by_name = {o.ellimann.part_name: o for o in ellipsoid_objects(collection)}
    missing = [name for name in mannequin.topology.names if name not in by_name]
    extra = [name for name in by_name if name not in mannequin.topology.index]
    if extra or len(missing) > len(mannequin.topology) // 2:  # another topology: the 40 and the fine one
        raise MannequinError(
            [
                Problem(
                    "",
                    "collection",
                    f"'{collection.name}' has {len(by_name)} ellipsoids, the mannequin {len(mannequin.topology)}: "
                    "a mannequin of another topology cannot be moved onto it; synthesize a new one",
                )
            ]
        )
    if missing:
        raise MannequinError([Problem(n, "collection", f"has no object in '{collection.name}'") for n in missing])
    write_frames(
        [by_name[name] for name in mannequin.topology.names], mannequin.rotation, mannequin.center, mannequin.semi_axes
    )
    write_collection_props(collection, mannequin)


def write_measured(collection, measured):
    """Store m_T (cm dict) on the collection."""
    collection.ellimann.measured = [float(measured[m]) for m in MEASUREMENTS]
    collection.ellimann.has_measured = True


def mannequin_collections(scene=None):
    """All mannequin collections in the scene's hierarchy."""
    root = (scene or bpy.context.scene).collection
    return [c for c in root.children_recursive if c.ellimann.is_mannequin]


def objects_recursive(collection):
    """Objects of a collection and its children, each once. Use this, not ``Collection.all_objects``: reading
    ``all_objects`` crashed the bpy module in ElliMann's headless runs."""
    objects = list(collection.objects)
    for child in collection.children_recursive:
        objects += [o for o in child.objects if o not in objects]
    return objects
