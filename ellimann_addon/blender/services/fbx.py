"""An avatar for garment tools as FBX, through Blender's exporter: a mannequin's skin, linearly skinned on a clean
skeleton (the 24 SMPL bones, no leaf bones, no constraints), Y up, in the A-pose or a T-pose, under a triangle
budget, optionally with its pieces beside it as a collision proxy.

The arrays come from the core (``core.formats.avatar``: the weights, the pose, the proxy, the measuring); this
module only decimates (Blender's Decimate modifier, symmetric in x, its vertex groups interpolated), looks up each
decimated vertex's nearest original one (a KD-tree), builds the scene and exports. A decimated avatar is measured
again, in the A-pose where the measurements are defined, and refused (ElliMannError naming the measurement and by
how much, nothing written) when it misses the request by more than the tolerance.

The FBX: one armature (the 24 bones, SMPL's or Mixamo's names), the skin (one mesh, a vertex group per bone it
follows, an Armature modifier: FBX's linear skin clusters), the proxy (one mesh, each piece rigid on its bone),
axes -Z forward and Y up (the body faces +Z, as in ElliMann's OBJ and glTF files), metres written with Blender's
unit scale. Written atomically (``core.files.atomic_output``).
"""

from dataclasses import dataclass

import bpy
import numpy as np
from mathutils.kdtree import KDTree

from ...core.errors import ElliMannError
from ...core.files import atomic_output
from ...core.formats.avatar import (
    DECIMATED_TOLERANCE_CM,
    GARMENT_TOOL_TRIANGLES,
    bone_names,
    check_avatar_options,
    dense_weights,
    misses,
    posed_avatar,
    proxy_mesh,
    remeasure,
)
from ...core.mannequin.skeleton import JOINT_NAMES
from ...core.pose.kinematics import require_joints
from ..bridge.convert import mesh_from_arrays, new_collection, world_triangles
from .chatter import blender_output
from .rig import bare_armature, bind_armature, set_bone_weights
from .scene import empty_scene

SKIN_NAME = "ElliMann Avatar"
PROXY_NAME = "ElliMann Collision Proxy"
DECIMATE_ROUNDS = 4  # tries to get under the budget (collapse lands near, not exactly at, the ratio asked)
FBX_OPTIONS = {
    "use_selection": True,
    "object_types": {"ARMATURE", "MESH"},
    "use_mesh_modifiers": False,  # the Armature modifier is the skin clusters, not baked into the mesh
    "mesh_smooth_type": "FACE",
    "add_leaf_bones": False,
    "primary_bone_axis": "Y",
    "secondary_bone_axis": "X",
    "armature_nodetype": "NULL",
    "bake_anim": False,
    "axis_forward": "-Z",
    "axis_up": "Y",
    "global_scale": 1.0,
    "apply_unit_scale": True,
    "apply_scale_options": "FBX_SCALE_NONE",
    "path_mode": "AUTO",
}


@dataclass
class FbxAvatar:
    """What was written: the ``path``, the skin's ``triangles`` (``decimated`` from how many, or None), the
    avatar's ``measured`` values (cm, A-pose, of the skin as written) against ``request``, the bones' names, the
    pose and the joints it clamped, the objects written (for tests: their names)."""

    path: str
    triangles: int
    decimated: int
    measured: dict
    request: dict
    bones: list
    pose: str
    clamped: list
    objects: list


def write_fbx(
    path,
    mannequin,
    skin,
    request=None,
    pose="a_pose",
    naming="smpl",
    pieces=False,
    max_triangles=GARMENT_TOOL_TRIANGLES,
    tolerance_cm=DECIMATED_TOLERANCE_CM,
):
    """Write the avatar of ``mannequin`` (with joints) and its core ``skin`` (``core.skin.surface.Skin``) to ``path``.

    ``request`` {key: cm}: what the avatar must measure (default the mannequin's target five); ``pose`` a_pose or
    t_pose; ``naming`` smpl or mixamo; ``pieces``: the collision proxy beside the skin; ``max_triangles``: the
    skin's budget (None: as it is). ElliMannError (one line) before anything is written: a bad option, no joints,
    a decimated avatar missing the request by more than ``tolerance_cm``. Returns an FbxAvatar."""
    check_avatar_options(pose, naming, max_triangles)
    require_joints(mannequin)
    names = bone_names(naming)
    request = dict(request if request is not None else (mannequin.measurements or {}))
    vertices, faces, weights = skin.vertices, skin.faces, dense_weights(skin)
    before = None
    if max_triangles is not None and len(faces) > max_triangles:
        before = len(faces)
        vertices, faces, weights = decimate(vertices, faces, weights, max_triangles)
        nearest = nearest_vertices(skin.vertices, vertices)
    else:
        nearest = np.arange(len(vertices))
    measured, _ = remeasure(skin, vertices, faces, nearest)
    missed = misses(measured, request, tolerance_cm)
    if missed:
        key, off = missed[0]
        what = "could not be measured" if not np.isfinite(off) else f"misses the request by {off:+.2f} cm"
        raise ElliMannError(
            f"fbx: the avatar ({len(faces):,} triangles) {what} for {key} (tolerance {tolerance_cm:g} cm); "
            "raise the triangle budget (--max-triangles)"
        )
    avatar = posed_avatar(mannequin, vertices, weights, pose)
    with blender_output():
        empty_scene()
        collection = new_collection(SKIN_NAME)
        rig = bare_armature(f"{SKIN_NAME} Rig", avatar.mannequin.joints, collection)
        exported = [rig, _skinned_object(SKIN_NAME, avatar.vertices, faces, weights, collection, rig)]
        if pieces:
            proxy_vertices, proxy_faces, proxy_bones = proxy_mesh(avatar.mannequin)
            rigid = np.zeros((len(proxy_vertices), len(JOINT_NAMES)))
            rigid[np.arange(len(proxy_vertices)), proxy_bones] = 1.0
            exported.append(_skinned_object(PROXY_NAME, proxy_vertices, proxy_faces, rigid, collection, rig))
        rename_bones(rig, exported[1:], names)
        _export(path, exported)
    return FbxAvatar(
        str(path), len(faces), before, measured, request, names, pose, avatar.reports, [o.name for o in exported]
    )


def _skinned_object(name, vertices, faces, weights, collection, rig):
    mesh = mesh_from_arrays(name, vertices, faces)
    mesh.shade_smooth()
    obj = bpy.data.objects.new(name, mesh)
    collection.objects.link(obj)
    set_bone_weights(obj, {JOINT_NAMES[j]: weights[:, j] for j in range(len(JOINT_NAMES)) if weights[:, j].any()})
    bind_armature(obj, rig)
    return obj


def rename_bones(rig, objects, names):
    """Rename the rig's bones (joint order) to ``names``, and the objects' vertex groups with them."""
    old = [bone.name for bone in rig.data.bones]
    renamed = dict(zip(JOINT_NAMES, names))
    for bone in rig.data.bones:
        bone.name = renamed[bone.name]
    for obj in objects:
        for group in obj.vertex_groups:
            if group.name in renamed and group.name in old:
                group.name = renamed[group.name]


def _export(path, objects):
    view_layer = bpy.context.view_layer
    view_layer.update()
    for obj in view_layer.objects:
        obj.select_set(obj in objects)
    view_layer.objects.active = objects[0]
    with atomic_output(path) as temp:
        bpy.ops.export_scene.fbx(filepath=temp, check_existing=False, **FBX_OPTIONS)


def decimate(vertices, faces, weights, budget):
    """(vertices, faces, weights (V, 24)) of a mesh decimated (Blender's collapse, symmetric in x, vertex groups
    interpolated) to at most ``budget`` triangles; ElliMannError if it cannot be."""
    mesh = mesh_from_arrays("ElliMann Decimate", vertices, faces)
    obj = bpy.data.objects.new("ElliMann Decimate", mesh)
    bpy.context.scene.collection.objects.link(obj)
    try:
        set_bone_weights(obj, {JOINT_NAMES[j]: weights[:, j] for j in range(len(JOINT_NAMES)) if weights[:, j].any()})
        ratio = budget / len(faces)
        for _ in range(DECIMATE_ROUNDS):
            modifier = obj.modifiers.new("Decimate", "DECIMATE")
            modifier.decimate_type = "COLLAPSE"
            modifier.ratio = ratio
            modifier.use_symmetry, modifier.symmetry_axis = True, "X"
            with bpy.context.temp_override(object=obj, active_object=obj, selected_objects=[obj]), blender_output():
                bpy.ops.object.modifier_apply(modifier=modifier.name)
            kept, triangles = world_triangles(obj)
            if len(triangles) <= budget:
                return kept, triangles, _group_weights(obj)
            ratio = budget / len(triangles) * 0.99
        raise ElliMannError(f"fbx: the skin could not be decimated to {budget:,} triangles ({len(triangles):,})")
    finally:
        bpy.data.objects.remove(obj)
        bpy.data.meshes.remove(mesh)


def _group_weights(obj):
    """(V, 24) of a mesh object's bone groups (each vertex's weights normalised, as the Armature modifier does)."""
    column = {group.index: JOINT_NAMES.index(group.name) for group in obj.vertex_groups if group.name in JOINT_NAMES}
    table = np.zeros((len(obj.data.vertices), len(JOINT_NAMES)))
    for vertex in obj.data.vertices:
        for element in vertex.groups:
            if element.group in column:
                table[vertex.index, column[element.group]] = element.weight
    total = table.sum(axis=1, keepdims=True)
    if np.any(total <= 0):
        raise ElliMannError("fbx: the decimated skin has a vertex that follows no bone")
    return table / total


def nearest_vertices(points, queries):
    """(Q,) index into ``points`` (P, 3) of the nearest to each of ``queries`` (Q, 3)."""
    tree = KDTree(len(points))
    for i, point in enumerate(points):
        tree.insert(point, i)
    tree.balance()
    return np.array([tree.find(query)[1] for query in queries], dtype=np.int64)
