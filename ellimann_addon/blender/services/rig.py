"""A mannequin's armature: bones at its joints, its pieces bound to them, poses and actions on it.

The armature object (tagged ``ellimann_rig``) lives in the mannequin's collection, one bone per joint
with the SMPL names; its layout (heads, tails, frames, limits) comes from ``core.pose.bones``. Each piece is
bound rigidly by an Armature modifier and one vertex group weighted 1.0 to its bone (ellipsoids share
one unit-sphere mesh per bone, since vertex group names live on the mesh), not parented to a bone:
the glTF exporter writes that as a skin, a cloth collider built the same way follows the deformed
mesh, and the objects' own matrices stay the rest pose, so m_T read from the scene is always the rest
pose's. A cushion joining pieces on two bones gets both bones' groups with per-vertex weights; a skin
(``services.skin``) comes with its own smooth weights and is only bound. Rotation limits are Limit Rotation
constraints in each bone's local space (exactly the core's ranges: ``core.pose.bones.bone_limit``).

Everything is computed before the scene changes; building raises ElliMannError without touching it.
"""

import bpy
import numpy as np
from mathutils import Matrix, Vector

from ...core.errors import ElliMannError
from ...core.geometry.cushion import cushion_meshes
from ...core.geometry.mesh import icosphere_level
from ...core.mannequin.skeleton import (
    JOINT_INDEX,
    JOINT_NAMES,
    PARENTS,
    cross_joint_pairs,
    joint_frames,
    limits,
    part_bones,
)
from ...core.pose import bones as core_bones
from ...core.pose.bone_match import PREFERRED_CHILD
from ...core.pose.kinematics import require_joints
from ...core.pose.motion import clamped_motion, loop_drift
from ...core.pose.posed_pieces import clip_convex_mesh
from ...core.pose.standard import WALK_FPS
from ..bridge.built import built_objects
from ..bridge.convert import RIG_KEY, ellipsoid_objects, mesh_from_arrays, rig_object, unit_sphere_mesh, world_triangles

FREE_RANGE = 2 * np.pi - 1e-9  # an axis whose range spans a whole turn gets no limit (the root)
MODIFIER_NAME = "ElliMann Rig"
CONSTRAINT_NAME = "ElliMann Limits"
UNIT_SPHERE_BONE_KEY = "ellimann_unit_sphere_bone"  # on a per-bone copy of the unit sphere: the bone's name
HULL_LEVEL_KEY = "ellimann_hull_level"  # on a cushion's halves: the icosphere level of the hull they were cut from
SOURCE_ATTRIBUTES = ("ellimann_hull_first", "ellimann_hull_second", "ellimann_hull_share")  # where each vertex is
WEIGHT_STEPS = 1024  # a vertex group weight's resolution


# ------------------------------------------------------------------------------------------------ lookups


def bone_frames(rig):
    """(n, 3, 3) rest frames of the rig's bones in bone order (columns = the bone's axes, armature space)."""
    return np.array([np.array(b.matrix_local)[:3, :3] for b in rig.data.bones])


# ------------------------------------------------------------------------------------------------ building


def check_rig(mannequin):
    """Raise ElliMannError (MannequinError naming the parts) unless ``mannequin`` can be rigged: it has joints
    and every part rides on a bone. Returns (joints, the bone index of each part)."""
    return require_joints(mannequin), part_bones(mannequin.topology)


def build_rig(collection, mannequin):
    """Build (or rebuild) the armature of ``collection`` from ``mannequin`` (the core mannequin it holds, with
    joints) and bind its pieces and built cushions; returns the armature object.

    Raises ElliMannError before anything changes if the mannequin has no joints or a part has no bone.
    """
    joints, bones = check_rig(mannequin)
    layout = skeleton_layout(joints)
    frames, ranges = joint_frames(joints), limits(joints)
    constraint_limits = {}
    for index, bone in enumerate(layout):
        spans = [None if hi - lo >= FREE_RANGE else (lo, hi) for lo, hi in ranges[index]]
        if any(span is not None for span in spans):
            constraint_limits[bone.name] = core_bones.bone_limit(bone, frames[index], spans)
    bone_of = {name: JOINT_NAMES[bone] for name, bone in zip(mannequin.topology.names, bones)}
    objects = ellipsoid_objects(collection)
    missing = [o.ellimann.part_name for o in objects if o.ellimann.part_name not in bone_of]
    if missing:
        raise ElliMannError(f"bones: '{collection.name}' holds part '{missing[0]}', which its mannequin lacks")
    view_layer = bpy.context.view_layer
    view_layer.update()  # objects just linked get their view-layer bases
    if any(view_layer.objects.get(o.name) != o for o in objects[:1]):  # Edit Mode needs the armature there
        raise ElliMannError(
            f"collection: '{collection.name}' is not in view layer '{view_layer.name}' (include it there to rig it)"
        )
    remove_rig(collection)
    rig = _armature_object(f"{collection.name} Rig", layout, collection)
    rig[RIG_KEY] = collection.name
    for bone_name, limit in constraint_limits.items():
        _limit_rotation(rig.pose.bones[bone_name], limit)
    for obj in objects:
        bind_rigid(obj, rig, bone_of[obj.ellimann.part_name])
    bind_cushions(collection, mannequin, rig)
    for skin in built_objects(collection, "SKIN"):  # its bone groups are its own (services.skin): only bound
        bind_armature(skin, rig)
    return rig


def skeleton_layout(joints):
    """The bones (``core.pose.bones.Bone``) of SMPL joints at ``joints`` (24, 3)."""
    return core_bones.layout_bones(JOINT_NAMES, joints, PARENTS, joint_frames(joints), PREFERRED_CHILD)


def bare_armature(name, joints, collection):
    """An armature object at ``joints`` in ``collection``, without limits or bound pieces (what a drape's
    colliders ride on: its motion is clamped already)."""
    return _armature_object(name, skeleton_layout(joints), collection)


def bind_piece(obj, rig, bone_name):
    """Bind any mesh object rigidly to one bone of ``rig`` (its mesh made its own first if it is shared)."""
    if obj.data.users > 1:
        obj.data = obj.data.copy()
    set_bone_weights(obj, {bone_name: np.ones(len(obj.data.vertices))})
    bind_armature(obj, rig)


def bind_weights(obj, rig, weights):
    """Bind a mesh object to ``rig`` with per-vertex weights {bone name: (V,)} (its own mesh, not shared)."""
    set_bone_weights(obj, weights)
    bind_armature(obj, rig)


def bind_across(obj, rig, point, toward, first_bone, second_bone):
    """Bind a convex mesh object to two bones, cut at the plane through ``point`` normal to ``toward``."""
    _split_at_joint(obj, point, toward, first_bone, second_bone)
    bind_armature(obj, rig)


def _armature_object(name, layout, collection):
    """A new armature object in ``collection`` with the bones of ``layout``, made in Edit Mode headless
    (edit bones exist only there; mode_set works on the view layer's active object, restored after)."""
    armature = bpy.data.armatures.new(name)
    armature.display_type = "STICK"
    rig = bpy.data.objects.new(name, armature)
    rig.show_in_front = True
    collection.objects.link(rig)
    view_layer = bpy.context.view_layer
    view_layer.update()
    previous = view_layer.objects.active
    view_layer.objects.active = rig
    try:
        bpy.ops.object.mode_set(mode="EDIT")
        edit_bones = []
        for bone in layout:
            edit = armature.edit_bones.new(bone.name)
            edit.head, edit.tail = Vector(bone.head), Vector(bone.tail)
            edit.align_roll(Vector(bone.frame[:, 2]))  # the bone's Z axis: fixes its roll, so X too
            edit_bones.append(edit)
        for bone, edit in zip(layout, edit_bones):
            if bone.parent >= 0:
                edit.parent = edit_bones[bone.parent]
        bpy.ops.object.mode_set(mode="OBJECT")
    finally:
        view_layer.objects.active = previous
    for pose_bone in rig.pose.bones:
        pose_bone.rotation_mode = "QUATERNION"
    return rig


def _limit_rotation(pose_bone, limit):
    constraint = pose_bone.constraints.new("LIMIT_ROTATION")
    constraint.name = CONSTRAINT_NAME
    constraint.owner_space = "LOCAL"
    constraint.euler_order = limit.euler_order
    for axis, span in zip("xyz", limit.ranges):
        setattr(constraint, f"use_limit_{axis}", span is not None)
        if span is not None:
            setattr(constraint, f"min_{axis}", span[0])
            setattr(constraint, f"max_{axis}", span[1])


def unit_sphere_for_bone(bone_name):
    """The unit-sphere mesh whose one vertex group, weighted 1.0 everywhere, is named after ``bone_name``."""
    for mesh in bpy.data.meshes:
        if mesh.get(UNIT_SPHERE_BONE_KEY) == bone_name:
            return mesh
    mesh = unit_sphere_mesh().copy()
    mesh.name = f"{mesh.name} {bone_name}"
    mesh[UNIT_SPHERE_BONE_KEY] = bone_name
    return mesh


def bind_rigid(obj, rig, bone_name):
    """Bind an object to one bone: all its vertices weighted 1.0 (an ellipsoid gets the shared per-bone
    unit sphere, other meshes their own group), an Armature modifier, the rig as its parent (world kept)."""
    if obj.ellimann.kind == "ELLIPSOID":
        obj.data = unit_sphere_for_bone(bone_name)
        if bone_name not in obj.vertex_groups:
            obj.vertex_groups.new(name=bone_name).add(range(len(obj.data.vertices)), 1.0, "REPLACE")
    else:
        set_bone_weights(obj, {bone_name: np.ones(len(obj.data.vertices))})
    bind_armature(obj, rig)


def set_bone_weights(obj, weights):
    """Replace the object's bone groups (those named after joints) by ``weights`` {bone name: (V,)}; other groups
    (a cloth's pins) stay. Weights are kept to 1/WEIGHT_STEPS (vertex groups are filled one value at a time: a
    skin's smooth weights would take a call per vertex); the Armature modifier and glTF normalise each vertex's."""
    for group in [g for g in obj.vertex_groups if g.name in JOINT_INDEX]:
        obj.vertex_groups.remove(group)
    for bone_name, values in weights.items():
        values = np.round(np.asarray(values, dtype=float) * WEIGHT_STEPS) / WEIGHT_STEPS
        group = obj.vertex_groups.new(name=bone_name)
        for value in np.unique(values[values > 0]):
            group.add([int(i) for i in np.flatnonzero(values == value)], float(value), "REPLACE")


def bind_armature(obj, rig):
    """An Armature modifier on ``rig`` (first in the stack) for an object whose bone groups are set, parented to the
    rig with its world matrix kept."""
    modifier = obj.modifiers.get(MODIFIER_NAME) or obj.modifiers.new(MODIFIER_NAME, "ARMATURE")
    modifier.object = rig
    modifier.use_vertex_groups, modifier.use_bone_envelopes = True, False
    index = list(obj.modifiers).index(modifier)
    if index:  # deform first: a Collision or Cloth modifier after it sees the posed mesh
        obj.modifiers.move(index, 0)
    world = obj.matrix_world.copy()
    obj.parent = rig
    obj.matrix_parent_inverse = rig.matrix_world.inverted()
    obj.matrix_world = world


def bind_cushions(collection, mannequin, rig=None):
    """Bind the built cushions of ``collection`` to its rig (if it has one). A cushion on one bone follows it
    rigidly; one across a joint is cut there into two convex halves, as ``core.pose.posed_pieces.PosingRig`` does (the
    plane through the joint across the line between its two parts' centres), each half riding on its own
    part's bone: bent, the halves open on the outside and overlap on the inside instead of webbing across."""
    rig = rig or rig_object(collection)
    if rig is None:
        return
    topology = mannequin.topology
    bones = part_bones(topology)
    crossing = {(topology.names[i], topology.names[j]): joint for i, j, joint in cross_joint_pairs(topology)}
    joints = require_joints(mannequin)
    for cushion in built_objects(collection, "CUSHION"):
        first, second = cushion.ellimann.part_name, cushion.ellimann.partner
        if first not in topology.index or second not in topology.index:
            continue
        first_bone = JOINT_NAMES[bones[topology.index[first]]]
        second_bone = JOINT_NAMES[bones[topology.index[second]]]
        joint = crossing.get((first, second), crossing.get((second, first)))
        if joint is None:
            set_bone_weights(cushion, {first_bone: np.ones(len(cushion.data.vertices))})
        else:
            if cushion.data.get(HULL_LEVEL_KEY) is not None:  # cut before (a rig built again): the whole hull first
                _whole_hull(cushion, mannequin, (topology.index[first], topology.index[second]))
            _split_at_joint(
                cushion,
                joints[joint],
                mannequin.center[topology.index[second]] - mannequin.center[topology.index[first]],
                first_bone,
                second_bone,
            )
        bind_armature(cushion, rig)


def _split_at_joint(cushion, point, toward, first_bone, second_bone):
    """Replace a cushion's mesh by its two halves either side of the plane through ``point`` normal to
    ``toward`` (world), one vertex group each. A hull at an icosphere level (as built) keeps where each half's
    vertices come from (:func:`split_sources`), so that live updates move the halves in place."""
    vertices, faces = world_triangles(cushion)
    level = icosphere_level(len(vertices)) if cushion.data.get(HULL_LEVEL_KEY) is None else None
    halves = [
        clip_convex_mesh(vertices, faces, point, normal, sources=True) for normal in (toward, -np.asarray(toward))
    ]
    kept = [(half, bone) for half, bone in zip(halves, (first_bone, second_bone)) if half is not None]
    sizes = [len(half[0]) for half, _ in kept]
    owner = np.repeat(np.arange(len(kept)), sizes)
    weights = {bone: (owner == k).astype(float) for k, (_, bone) in enumerate(kept)}
    inverse = np.linalg.inv(np.array(cushion.matrix_world))
    local = np.concatenate([half[0] for half, _ in kept]) @ inverse[:3, :3].T + inverse[:3, 3]
    faces = np.concatenate([np.asarray(half[1]) + start for (half, _), start in zip(kept, np.cumsum([0] + sizes[:-1]))])
    old = cushion.data
    mesh = mesh_from_arrays(old.name, local, faces)
    mesh.shade_smooth()
    if level is not None:
        sources = [np.concatenate(column) for column in zip(*(half[2] for half, _ in kept))]
        for name, kind, values in zip(SOURCE_ATTRIBUTES, ("INT", "INT", "FLOAT"), sources):
            mesh.attributes.new(name, kind, "POINT").data.foreach_set("value", values)
        mesh[HULL_LEVEL_KEY] = level
    cushion.data = mesh
    if old.users == 0:
        bpy.data.meshes.remove(old)
    mesh.name = cushion.name
    set_bone_weights(cushion, weights)


def _whole_hull(cushion, mannequin, pair):
    """Give a cushion that was cut at its joint the whole hull of its pair back, at the level it was cut from."""
    ((vertices, faces),) = cushion_meshes(
        [tuple((mannequin.rotation[i], mannequin.center[i], mannequin.semi_axes[i]) for i in pair)],
        int(cushion.data[HULL_LEVEL_KEY]),
    )
    inverse = np.linalg.inv(np.array(cushion.matrix_world))
    old = cushion.data
    cushion.data = mesh_from_arrays(old.name, vertices @ inverse[:3, :3].T + inverse[:3, 3], faces)
    if old.users == 0:
        bpy.data.meshes.remove(old)


def split_sources(mesh):
    """(the icosphere level of the hull a split cushion was cut from, the sources of its vertices as
    ``core.pose.posed_pieces.clipped_vertices`` takes them), or None for a mesh that is not such halves."""
    level = mesh.get(HULL_LEVEL_KEY)
    if level is None or any(name not in mesh.attributes for name in SOURCE_ATTRIBUTES):
        return None
    count = len(mesh.vertices)
    columns = [np.empty(count, dtype=np.int32), np.empty(count, dtype=np.int32), np.empty(count, dtype=np.float32)]
    for name, column in zip(SOURCE_ATTRIBUTES, columns):
        mesh.attributes[name].data.foreach_get("value", column)
    return int(level), (columns[0], columns[1], columns[2].astype(float))


def remove_rig(collection):
    """Remove a mannequin's armature and unbind its pieces (shared unit sphere back, world matrices kept)."""
    rig = rig_object(collection)
    if rig is None:
        return False
    shared = unit_sphere_mesh()
    for obj in [o for o in bpy.data.objects if o.parent == rig]:
        world = obj.matrix_world.copy()
        modifier = obj.modifiers.get(MODIFIER_NAME)
        if modifier is not None:
            obj.modifiers.remove(modifier)
        if obj.ellimann.kind == "ELLIPSOID" and obj.data.get(UNIT_SPHERE_BONE_KEY):
            obj.data = shared
        elif obj.type == "MESH" and obj.ellimann.kind != "SKIN":  # a skin's weights are its own, kept
            for group in [g for g in obj.vertex_groups if g.name in JOINT_INDEX]:
                obj.vertex_groups.remove(group)
        obj.parent = None
        obj.matrix_world = world
    armature = rig.data
    bpy.data.objects.remove(rig)
    if armature.users == 0:
        bpy.data.armatures.remove(armature)
    for mesh in [m for m in bpy.data.meshes if m.get(UNIT_SPHERE_BONE_KEY) and m.users == 0]:
        bpy.data.meshes.remove(mesh)
    return True


# ------------------------------------------------------------------------------------------------ posing


def pose_channels(rig, names, local_rotations, translation=None):
    """(quaternions (..., n, 4) w-first, root locations (..., 3)) in the rig's bone order, of core local
    rotations (..., n, 3, 3) of the joints ``names`` (the core's order) and root translations (..., 3).
    Joints the rig lacks are left out; bones not in ``names`` stay at rest."""
    order = {name: i for i, name in enumerate(names)}
    local_rotations = np.asarray(local_rotations, float)
    rig_rotations = np.broadcast_to(np.eye(3), local_rotations.shape[:-3] + (len(rig.data.bones), 3, 3)).copy()
    for index, bone in enumerate(rig.data.bones):
        if bone.name in order:
            rig_rotations[..., index, :, :] = local_rotations[..., order[bone.name], :, :]
    frames = bone_frames(rig)
    basis = core_bones.bone_rotations(frames, rig_rotations)
    flat = basis.reshape(-1, 3, 3)
    quaternions = np.array([Matrix(m.tolist()).to_quaternion()[:] for m in flat]).reshape(basis.shape[:-2] + (4,))
    root = next(i for i, b in enumerate(rig.data.bones) if b.parent is None)
    translation = np.zeros(basis.shape[:-3] + (3,)) if translation is None else np.asarray(translation, float)
    return quaternions, core_bones.root_location(frames[root], translation)


def set_pose(rig, names, local_rotations, translation=None):
    """Pose the rig (no action: an assigned one is unassigned, or it would take the bones back)."""
    if rig.animation_data is not None:
        rig.animation_data.action = None
    quaternions, location = pose_channels(rig, names, local_rotations, translation)
    for bone, quaternion in zip(rig.data.bones, quaternions):
        pose_bone = rig.pose.bones[bone.name]
        pose_bone.rotation_mode = "QUATERNION"
        pose_bone.rotation_quaternion = quaternion
        pose_bone.location = (0.0, 0.0, 0.0)
        pose_bone.scale = (1.0, 1.0, 1.0)
    root = next(b for b in rig.pose.bones if b.parent is None)
    root.location = location


def rest_pose(rig):
    """Every bone at rest, no action."""
    set_pose(rig, [], np.zeros((0, 3, 3)))


def bake_action(rig, names, local_rotations, translations, name, start=1, loop_translation=None):
    """A new action on the rig, one key per frame from ``start``: rotations (F, n, 3, 3) of the joints
    ``names``, root translations (F, 3), linear between keys. ``loop_translation`` (3,): the clip loops,
    F frames long: frame F is keyed as frame 0 again with the root at ``loop_translation`` (where the
    next cycle starts, e.g. one stride further on), and every curve repeats (a Cycles modifier, the root's
    location shifted by that much each cycle). Returns the action."""
    quaternions, locations = pose_channels(rig, names, local_rotations, translations)
    if loop_translation is not None:
        quaternions = np.concatenate([quaternions, quaternions[:1]])
        closing = pose_channels(rig, names, local_rotations[:1], np.asarray(loop_translation, float)[None])[1]
        locations = np.concatenate([locations, closing])
    # Consecutive quaternions on one side: interpolating q to -q would spin the bone the long way.
    for frame in range(1, len(quaternions)):
        flip = np.sum(quaternions[frame] * quaternions[frame - 1], axis=-1) < 0
        quaternions[frame][flip] *= -1
    rig.animation_data_create()
    action = bpy.data.actions.new(name)
    rig.animation_data.action = action
    root = next(b for b in rig.pose.bones if b.parent is None)
    pose_bones = [rig.pose.bones[bone.name] for bone in rig.data.bones]
    # The first key of each channel by keyframe_insert (it makes the curves, and on 4.4+ the action's slot); the
    # others written into the curves at once (a key at a time takes 15 s for a 1,000-frame clip).
    for pose_bone, quaternion in zip(pose_bones, quaternions[0]):
        pose_bone.rotation_quaternion = quaternion
        pose_bone.keyframe_insert("rotation_quaternion", frame=start, group=pose_bone.name)
    root.location = locations[0]
    root.keyframe_insert("location", frame=start, group=root.name)
    curves = {(c.data_path, c.array_index): c for c in action_fcurves(action, rig)}
    times = start + np.arange(len(quaternions), dtype=float)
    for index, pose_bone in enumerate(pose_bones):
        for k in range(4):
            _set_keys(curves[(pose_bone.path_from_id("rotation_quaternion"), k)], times, quaternions[:, index, k])
    for k in range(3):
        _set_keys(curves[(root.path_from_id("location"), k)], times, locations[:, k])
    for curve in action_fcurves(action, rig):
        if loop_translation is not None:
            cycles = curve.modifiers.new("CYCLES")
            if curve.data_path.endswith("location"):
                cycles.mode_before = cycles.mode_after = "REPEAT_OFFSET"
    return action


def _set_keys(curve, times, values):
    """``curve``'s keys at ``times``, linear between them (the first already there)."""
    points = curve.keyframe_points
    points.add(len(times) - len(points))
    points.foreach_set("co", np.column_stack([times, values]).ravel())
    for point in points:
        point.interpolation = "LINEAR"
    curve.update()


def apply_pose(rig, pose):
    """Pose the rig in a core ``Pose`` (SMPL joints)."""
    set_pose(rig, JOINT_NAMES, pose.rotations, pose.translation)


def apply_motion(rig, poses, name, start=1, loop=False):
    """Bake core poses (one per frame) as an action; ``loop``: a cycle whose next start is the first pose
    moved on by the clip's drift (``core.pose.motion.loop_drift``: along the walking direction, -Y)."""
    rotations = np.stack([p.rotations for p in poses])
    translations = np.stack([p.translation for p in poses])
    closing = translations[0] + loop_drift(poses) if loop else None
    return bake_action(rig, JOINT_NAMES, rotations, translations, name, start, closing)


def pose_standard(rig, joints, name, scene, action_name=None):
    """Put ``rig`` (of a mannequin with rest ``joints``) in the standard pose ``name``; a motion (walk) becomes
    a looping action with the scene's frames 1..F at its frame rate, from frame 1. Joint angles beyond their
    limits are clamped. Returns (the poses, the clamp reports, the action or None). ElliMannError for an
    unknown name, before anything changes."""
    poses, reports, loops = clamped_motion(name, joints)
    if not loops:
        apply_pose(rig, poses[0])
        return poses, reports, None
    action = apply_motion(rig, poses, action_name or f"{rig.name} {name}", start=1, loop=True)
    scene.render.fps, scene.render.fps_base = WALK_FPS, 1.0
    scene.frame_start, scene.frame_end = 1, len(poses)
    scene.frame_set(1)
    return poses, reports, action


def action_fcurves(action, rig):
    """The F-curves of ``action`` as the rig uses it: Blender 4.x's ``action.fcurves``, or 4.4+'s
    channel bag of the rig's slot (5.0 has only that)."""
    if hasattr(action, "fcurves"):
        return action.fcurves
    from bpy_extras import anim_utils

    channelbag = anim_utils.action_get_channelbag_for_slot(action, rig.animation_data.action_slot)
    return channelbag.fcurves if channelbag is not None else []
