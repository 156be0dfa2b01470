"""Import BVH Motion: a clip read by Blender's BVH importer, mapped by bone names onto the active mannequin's
armature as an action; joint angles beyond their limits are clamped and reported by joint and frame."""

import os

import bpy
from bpy.props import StringProperty
from bpy_extras.io_utils import ImportHelper

from ....core.errors import ElliMannError
from ....core.mannequin.skeleton import JOINT_NAMES, PARENTS, RIG_NAME_MAPS, joint_of_bone
from ....core.pose.kinematics import Pose, clamp_pose
from ....core.pose.retarget import retarget
from ... import ids
from ...bridge.convert import read_joints, rig_object
from ...services.bvh import bvh_header, sample_bvh
from ...services.rig import PREFERRED_CHILD, apply_motion
from ..base import MannequinOperator, OperatorError, plural
from .operators import has_rig
from .props import RIG_LABELS

SHOWN_REPORTS = 5  # clamped angles listed one by one in the Info log; the rest are counted


def name_map(bone_names, rig="AUTO"):
    """(rig key, {clip bone: SMPL joint}) for the clip's bones: ``rig``'s map, or with AUTO the map that
    knows most of them (the first in RIG_NAME_MAPS on a tie)."""
    keys = list(RIG_NAME_MAPS) if rig == "AUTO" else [rig]
    found = {key: {b: joint_of_bone(key, b) for b in bone_names if joint_of_bone(key, b)} for key in keys}
    best = max(keys, key=lambda key: len(found[key]))
    return best, found[best]


def motion_onto(collection, path, rig="AUTO"):
    """(core poses, clamp reports, rig key, clip) of a BVH clip on a mannequin collection; ElliMannError
    (nothing changed) for a file that is not a BVH clip or whose bones no map knows."""
    joints = read_joints(collection)
    if joints is None:
        raise ElliMannError(f"joints: '{collection.name}' has no joints (rig it again: Add Armature)")
    names, _ = bvh_header(path)
    key, mapping = name_map(names, rig)
    if not mapping:
        shown = ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")
        which = "any of the maps (MakeHuman/CMU, Mixamo)" if rig == "AUTO" else f"the {RIG_LABELS.get(rig, rig)} map"
        raise ElliMannError(
            f"bones: none of the {len(names)} bones of {os.path.basename(path)} ({shown}) is in {which}"
        )
    clip = sample_bvh(path)
    rotations, translations = retarget(clip, JOINT_NAMES, joints, PARENTS, mapping, PREFERRED_CHILD)
    poses, reports = [], []
    for frame, (rotation, translation) in enumerate(zip(rotations, translations), start=1):
        pose, found = clamp_pose(Pose(rotation, translation, name=f"frame {frame}"), joints, frame=frame)
        poses.append(pose)
        reports += found
    return poses, reports, key, clip


class ELLIMANN_OT_import_bvh(MannequinOperator, ImportHelper, bpy.types.Operator):
    """Import a BVH clip onto the active mannequin's armature by bone names, clamping and reporting passed limits"""

    bl_idname = ids.IMPORT_BVH
    bl_label = "Import BVH Motion"
    bl_options = {"REGISTER", "UNDO"}
    OBJECT_MODE_ONLY = False

    filename_ext = ".bvh"
    filter_glob: StringProperty(default="*.bvh", options={"HIDDEN"}, description="Files shown in the browser")

    @classmethod
    def poll(cls, context):
        return hasattr(context.scene, "ellimann_pose") and has_rig(context)

    def run(self, context, collection):
        props = context.scene.ellimann_pose
        try:
            poses, reports, key, clip = motion_onto(collection, self.filepath, props.rig)
        except ElliMannError as error:
            raise OperatorError(f"Cannot import onto '{collection.name}': {error}") from error
        scene = context.scene
        name = os.path.splitext(os.path.basename(self.filepath))[0]
        action = apply_motion(rig_object(collection), poses, name)
        scene.render.fps, scene.render.fps_base = max(1, round(clip.fps)), 1.0
        scene.frame_start, scene.frame_end = 1, len(poses)
        scene.frame_set(1)
        for report in reports[:SHOWN_REPORTS]:
            self.report({"WARNING"}, f"clamped: {report}")
        clamped = f"; {plural(len(reports), 'joint angle')} clamped to the limits" if reports else ""
        if reports:
            clamped += f" (first: {reports[0]})"
        props.status = f"{name}: {len(poses)} frames ({RIG_LABELS.get(key, key)} names){clamped}"
        self.report(
            {"INFO"},
            f"Imported '{name}' onto '{collection.name}' as action '{action.name}': "
            f"{len(poses)} frames, {RIG_LABELS.get(key, key)} bone names{clamped}",
        )
        return {"FINISHED"}


classes = (ELLIMANN_OT_import_bvh,)
