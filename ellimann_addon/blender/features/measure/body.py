"""Measure Body Mesh: the five measurements and the extra ones of a selected mesh (a scan, a body from another
tool) standing upright in an A-pose, its arms found by geometry alone (``core.measure.body``)."""

import json

import bpy

from ....core.measure.body import measure_body_mesh
from ....core.measurements import measurement_line
from ....core.synthesis.bodies import labelled_arms
from ... import ids
from ...bridge.convert import world_triangles
from ...bridge.selection import owning_mannequin
from ..base import ElliMannOperator, OperatorError

RESULT_PROPERTY = "ellimann_measured"  # the object's custom property holding the last result (JSON, cm)


def is_body_mesh(obj):
    """A mesh object that is no part of an ElliMann mannequin (nor a piece ElliMann built from one)."""
    return obj is not None and obj.type == "MESH" and not obj.ellimann.is_part and owning_mannequin(obj) is None


def measure_object(obj, fractions=None):
    """(values {key: cm}, problems [lines]) of a mesh object in world space (Blender: Z up, metres)."""
    vertices, faces = world_triangles(obj)
    result = measure_body_mesh(vertices, faces, fractions, arms=labelled_arms(faces))
    return result.values, result.problems


def values_line(values):
    return f"{measurement_line(values)} cm"


class ELLIMANN_OT_measure_body(ElliMannOperator, bpy.types.Operator):
    """Measure the active mesh as a standing A-pose body (the five and neck, upper arm, thigh, calf, crotch height, arm length) and store them on it"""  # noqa: E501

    bl_idname = ids.MEASURE_BODY
    bl_label = "Measure Body Mesh"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT" and is_body_mesh(context.active_object)

    def run(self, context):
        obj = context.active_object
        values, problems = measure_object(obj)
        if not values:
            raise OperatorError(f"'{obj.name}': {problems[0]}")
        obj[RESULT_PROPERTY] = json.dumps({key: round(value, 4) for key, value in values.items()})
        for problem in problems:
            self.report({"WARNING"}, f"'{obj.name}': {problem}")
        self.report({"INFO"}, f"'{obj.name}': {values_line(values)}")
        return {"FINISHED"}


classes = (ELLIMANN_OT_measure_body,)
