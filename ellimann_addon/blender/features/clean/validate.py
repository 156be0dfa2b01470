"""Validating a mannequin, and repairing ellipsoids a user broke (applied scale, negative scale, shear)."""

import bpy

from ....core.errors import FrameError
from ... import ids
from ...bridge.checks import FIXABLE, frame_issue, mannequin_problems, repaired_frame
from ...bridge.convert import ellipsoid_objects, unit_sphere_mesh, write_frames
from ..base import MannequinOperator, OperatorError, ScopedOperator, plural, scope_property


class ELLIMANN_OT_validate_mannequin(MannequinOperator, bpy.types.Operator):
    """Check the active mannequin's frames, topology and geometry; report every problem by ellipsoid name"""

    bl_idname = ids.VALIDATE_MANNEQUIN
    bl_label = "Validate"
    bl_options = {"REGISTER"}
    OBJECT_MODE_ONLY = False

    def run(self, context, collection):
        problems = mannequin_problems(collection)
        if problems:
            raise OperatorError(f"'{collection.name}' has {plural(len(problems), 'problem')}", problems)
        count = len(ellipsoid_objects(collection))
        self.report({"INFO"}, f"'{collection.name}' is a valid mannequin ({plural(count, 'ellipsoid')})")
        return {"FINISHED"}


class ELLIMANN_OT_fix_frames(ScopedOperator, bpy.types.Operator):
    """Repair ellipsoids with an applied scale, a negative scale or shear, keeping their shape and place"""

    bl_idname = ids.FIX_FRAMES
    bl_label = "Fix Frames"
    bl_options = {"REGISTER", "UNDO"}

    scope: scope_property("SELECTED")

    def run(self, context):
        broken = [(o, issue) for o in self.targets(context) if (issue := frame_issue(o)) is not None]
        if not broken:
            raise OperatorError("Nothing to fix: every ellipsoid is a valid frame")
        repairs, problems = [], []
        for obj, issue in broken:
            name = obj.ellimann.part_name or obj.name
            if issue.kind not in FIXABLE:
                problems.append(f"'{name}': {issue} (cannot be repaired automatically)")
                continue
            try:
                repairs.append((obj, issue.kind, repaired_frame(obj)))
            except FrameError as error:
                problems.append(f"'{name}': {error}")
        if not repairs:
            raise OperatorError("No ellipsoid could be repaired", problems)
        for obj, kind, (rotation, center, semi_axes) in repairs:
            if kind == "mesh":
                obj.data = unit_sphere_mesh()
            write_frames([obj], rotation[None], center[None], semi_axes[None])
        context.view_layer.update()  # children's world matrices are recomputed from their parents here
        unparented = []
        for obj, _, (rotation, center, semi_axes) in repairs:
            if obj.parent is not None and frame_issue(obj) is not None:
                # A sheared parent cannot give a child an orthogonal frame: detach, keeping the shape.
                obj.parent = None
                write_frames([obj], rotation[None], center[None], semi_axes[None])
                unparented.append(obj.ellimann.part_name or obj.name)
        for problem in problems:
            self.report({"WARNING"}, problem)
        if unparented:
            self.report({"WARNING"}, f"Cleared the parent of {', '.join(unparented)} (its scale sheared them)")
        self.report(
            {"INFO"},
            f"Repaired {plural(len(repairs), 'ellipsoid')}: "
            + ", ".join(f"{o.ellimann.part_name or o.name} ({kind})" for o, kind, _ in repairs),
        )
        return {"FINISHED"}


classes = (ELLIMANN_OT_validate_mannequin, ELLIMANN_OT_fix_frames)
