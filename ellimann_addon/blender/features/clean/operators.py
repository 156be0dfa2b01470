"""Cleaning (paper, Section 2.3.4): relabel axes against a reference, symmetrize central ellipsoids,
register a mannequin to the world frame."""

import bpy
import numpy as np
from bpy.props import StringProperty
from mathutils import Vector

from ....core.errors import MannequinError
from ....core.geometry.frames import relabel_to_reference, symmetrize_central
from ....core.mannequin.clean import register_to_world
from ....core.mannequin.topology import side_of_name
from ... import ids
from ...bridge.built import built_objects
from ...bridge.convert import (
    collection_to_mannequin,
    mannequin_collections,
    update_collection_geometry,
    write_frames,
)
from ...bridge.selection import active_mannequin, part_lookup
from ..base import (
    MannequinOperator,
    OperatorError,
    ScopedOperator,
    frames_or_cancel,
    plural,
    scope_property,
)

ROLE_PREFERENCE = ("base", "reference", "synthesized")


def default_reference(context):
    """Name of the mannequin to relabel against: another mannequin, a base one first."""
    active = active_mannequin(context)
    others = [c for c in mannequin_collections(context.scene) if c != active]
    others.sort(key=lambda c: ROLE_PREFERENCE.index(c.ellimann.role))
    return others[0].name if others else ""


class ELLIMANN_OT_relabel_axes(ScopedOperator, bpy.types.Operator):
    """Relabel and invert ellipsoid axes to agree with the same parts of a reference mannequin"""

    bl_idname = ids.RELABEL_AXES
    bl_label = "Relabel Axes"
    bl_options = {"REGISTER", "UNDO"}

    scope: scope_property("MANNEQUIN")
    reference: StringProperty(
        name="Reference",
        description="Mannequin collection whose ellipsoids' axes are the reference (matched by part name)",
    )

    def invoke(self, context, event):
        if not self.reference:
            self.reference = default_reference(context)
        return context.window_manager.invoke_props_dialog(self)

    def draw(self, context):
        self.layout.prop_search(self, "reference", bpy.data, "collections")
        self.layout.prop(self, "scope")

    def run(self, context):
        reference = bpy.data.collections.get(self.reference)
        if reference is None or not reference.ellimann.is_mannequin:
            raise OperatorError(f"Choose a reference mannequin collection ('{self.reference}' is not one)")
        objects = [o for o in self.targets(context) if reference.objects.get(o.name) != o]
        if not objects:
            raise OperatorError(
                "No ellipsoids to relabel outside the reference: select some, or make another mannequin active"
            )
        lookup = part_lookup(reference)
        matched = [o for o in objects if o.ellimann.part_name in lookup]
        missing = [o.ellimann.part_name for o in objects if o.ellimann.part_name not in lookup]
        if not matched:
            raise OperatorError(
                f"None of the {plural(len(objects), 'ellipsoid')} has a part of the same name in '{reference.name}'"
            )
        rotation, center, semi_axes = frames_or_cancel(matched)
        reference_rotation, _, _ = frames_or_cancel([lookup[o.ellimann.part_name] for o in matched])
        rotation, semi_axes, q = relabel_to_reference(rotation, semi_axes, reference_rotation)
        changed = ~np.all(np.isclose(q, np.eye(3)), axis=(1, 2))
        write_frames([o for o, c in zip(matched, changed) if c], rotation[changed], center[changed], semi_axes[changed])
        if missing:
            self.report({"WARNING"}, f"Not in '{reference.name}', left alone: {', '.join(missing)}")
        self.report(
            {"INFO"},
            f"Relabelled {plural(int(changed.sum()), 'ellipsoid')} to agree with "
            f"'{reference.name}'; {int((~changed).sum())} already agreed",
        )
        return {"FINISHED"}


class ELLIMANN_OT_symmetrize_central(ScopedOperator, bpy.types.Operator):
    """Make central ellipsoids symmetric about x = 0: one axis along world X, the centre on the plane"""

    bl_idname = ids.SYMMETRIZE_CENTRAL
    bl_label = "Symmetrize Central"
    bl_options = {"REGISTER", "UNDO"}

    scope: scope_property("MANNEQUIN")

    def run(self, context):
        objects = [o for o in self.targets(context) if side_of_name(o.ellimann.part_name) == "C"]
        if not objects:
            raise OperatorError("No central ellipsoids (names without .L/.R) to symmetrize")
        rotation, center, semi_axes = frames_or_cancel(objects)
        try:
            rotation, center = symmetrize_central(rotation, center)
        except ValueError as error:
            raise OperatorError(f"Cannot symmetrize: {error}") from error
        write_frames(objects, rotation, center, semi_axes)
        self.report({"INFO"}, f"Symmetrized {plural(len(objects), 'central ellipsoid')}")
        return {"FINISHED"}


class ELLIMANN_OT_register_mannequin(MannequinOperator, bpy.types.Operator):
    """Move the active mannequin to the world frame: feet on z = 0, trapezius centred on x = y = 0"""

    bl_idname = ids.REGISTER_MANNEQUIN
    bl_label = "Register to World"
    bl_options = {"REGISTER", "UNDO"}

    def run(self, context, collection):
        try:
            mannequin = collection_to_mannequin(collection)
            registered = register_to_world(mannequin)
        except MannequinError as error:
            raise OperatorError(f"Cannot register '{collection.name}'", error.problems) from error
        offset = registered.center[0] - mannequin.center[0]
        update_collection_geometry(collection, registered)
        for obj in built_objects(collection, "CUSHION") + built_objects(collection, "SECTION"):
            matrix = obj.matrix_world.copy()
            matrix.translation += Vector(offset.tolist())
            obj.matrix_world = matrix
        self.report(
            {"INFO"},
            f"Registered '{collection.name}': moved by ({offset[0]:+.4f}, {offset[1]:+.4f}, {offset[2]:+.4f}) m",
        )
        return {"FINISHED"}


classes = (ELLIMANN_OT_relabel_axes, ELLIMANN_OT_symmetrize_central, ELLIMANN_OT_register_mannequin)
