"""Tracing a Base Mannequin: new mannequin collection, add an ellipsoid, fit one to selected vertices."""

import bpy
import numpy as np
from bpy.props import EnumProperty, FloatVectorProperty, StringProperty

from ....core.fitting.point_fit import fit_ellipsoid
from ....core.geometry.ellipsoid import axis_extent
from ....core.mannequin.topology import NAME_PATTERN, Part, side_of_name
from ... import ids
from ...bridge.bodies import selection_trace
from ...bridge.convert import mesh_vertices, new_ellipsoid_object, write_trace
from ...bridge.props import ROLE_ITEMS
from ...bridge.selection import active_mannequin, new_mannequin_collection, part_lookup
from ..base import ElliMannOperator, OperatorError

DEFAULT_LABEL = "Ellipsoid"
FIT_MODE_ITEMS = (
    (
        "inscribed",
        "Inscribed",
        "Principal axes of the selection, sized so that no vertex of the mesh, selected or "
        "not, lies inside it: it stays inside the traced surface",
    ),
    ("moments", "Moments", "Principal axes and sizes from the second moments of the selected vertices"),
    ("enclosing", "Enclosing", "Principal axes of the selection, sized to enclose every selected vertex"),
)

PART_NAME = StringProperty(
    name="Part Name",
    description="Topology name such as '7.a Thigh.L' (the suffix .L/.R sets the side); empty: the next free "
    "number, with a side from where the ellipsoid lies",
)


def next_part_name(existing, center_x, half_width_x, label=DEFAULT_LABEL):
    """'<next free number>.a <label>[.L|.R]': lateral (.L at +X) only if it lies wholly on one side."""
    numbers = [int(m.group("number")) for name in existing if (m := NAME_PATTERN.match(name))]
    side = "" if abs(center_x) < half_width_x else (".L" if center_x > 0.0 else ".R")
    return f"{max(numbers, default=0) + 1}.a {label}{side}"


def add_part(operator, context, rotation, center, semi_axes):
    """Add the part to the active mannequin (a new one if none) under the operator's name or the next free one.

    Returns (object, collection, error); on error nothing was created.
    """
    collection = active_mannequin(context)
    existing = part_lookup(collection) if collection is not None else {}
    name = operator.part_name.strip() or next_part_name(existing, center[0], axis_extent(rotation, semi_axes, 0))
    if not NAME_PATTERN.match(name):
        return None, None, f"Part name '{name}' must look like '10.a Trapezius.L' (number.letter label[.L|.R])"
    if name in existing:
        return None, None, f"'{collection.name}' already has a part '{name}'"
    if collection is None:
        collection = new_mannequin_collection(context)
    part = Part(name, side_of_name(name), "", True, ("He",))
    return new_ellipsoid_object(part, rotation, center, semi_axes, collection), collection, None


class ELLIMANN_OT_new_mannequin(ElliMannOperator, bpy.types.Operator):
    """Create an empty mannequin collection and make it the active collection: new parts go into it"""

    bl_idname = ids.NEW_MANNEQUIN
    bl_label = "New Mannequin"
    bl_options = {"REGISTER", "UNDO"}

    name: StringProperty(
        name="Name",
        default="Mannequin",
        description="Name of the new mannequin collection (Blender adds a number if it is taken)",
    )
    role: EnumProperty(
        name="Role",
        items=ROLE_ITEMS,
        default="base",
        description="Role of the new mannequin: one traced over a reference body is the Base",
    )

    @classmethod
    def poll(cls, context):
        return context.scene is not None and context.view_layer is not None

    def run(self, context):
        collection = new_mannequin_collection(context, self.name.strip() or "Mannequin", self.role)
        self.report({"INFO"}, f"New {self.role} mannequin '{collection.name}'")
        return {"FINISHED"}


class ELLIMANN_OT_add_ellipsoid(ElliMannOperator, bpy.types.Operator):
    """Add an ellipsoid at the 3D cursor to the active mannequin (or to a new mannequin collection)"""

    bl_idname = ids.ADD_ELLIPSOID
    bl_label = "Add Ellipsoid"
    bl_options = {"REGISTER", "UNDO"}

    part_name: PART_NAME
    semi_axes: FloatVectorProperty(
        name="Semi-Axes",
        size=3,
        default=(0.05, 0.05, 0.05),
        min=1e-4,
        soft_max=1.0,
        subtype="XYZ_LENGTH",
        unit="LENGTH",
        description="Half-lengths of the ellipsoid along its local x, y, z (m)",
    )

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT" and context.scene is not None

    def run(self, context):
        center = np.array(context.scene.cursor.location)
        obj, collection, error = add_part(self, context, np.eye(3), center, np.array(self.semi_axes))
        if error:
            raise OperatorError(error)
        for other in context.selected_objects:
            other.select_set(False)
        obj.select_set(True)
        context.view_layer.objects.active = obj
        self.report({"INFO"}, f"Added '{obj.ellimann.part_name}' to '{collection.name}'")
        return {"FINISHED"}


def edit_mesh_world_vertices(context):
    """World coordinates of the vertices of every mesh in Edit Mode: (selected (n, 3), the others (m, 3))."""
    selected_chunks, other_chunks = [], []
    for obj in context.objects_in_mode:
        if obj.type != "MESH":
            continue
        obj.update_from_editmode()  # edit-mode changes reach obj.data only on request
        mesh = obj.data
        selected = np.zeros(len(mesh.vertices), dtype=bool)
        mesh.vertices.foreach_get("select", selected)
        matrix = np.array(obj.matrix_world)
        world = mesh_vertices(mesh) @ matrix[:3, :3].T + matrix[:3, 3]
        selected_chunks.append(world[selected])
        other_chunks.append(world[~selected])
    return tuple(np.concatenate(chunks) if chunks else np.zeros((0, 3)) for chunks in (selected_chunks, other_chunks))


def selected_traces(context, method):
    """The recorded selection (core.mannequin.traces.PartTrace) of every mesh in Edit Mode with selected vertices."""
    return [
        trace
        for obj in context.objects_in_mode
        if obj.type == "MESH" and (trace := selection_trace(obj, method)) is not None
    ]


class ELLIMANN_OT_fit_ellipsoid(ElliMannOperator, bpy.types.Operator):
    """Fit an ellipsoid to the selected vertices (principal axes) and add it to the active mannequin, recording them"""

    bl_idname = ids.FIT_ELLIPSOID
    bl_label = "Fit Ellipsoid to Selection"
    bl_options = {"REGISTER", "UNDO"}

    mode: EnumProperty(
        name="Size", items=FIT_MODE_ITEMS, default="inscribed", description="How big the fitted ellipsoid is"
    )
    part_name: PART_NAME

    @classmethod
    def poll(cls, context):
        return context.mode == "EDIT_MESH"

    def run(self, context):
        points, rest = edit_mesh_world_vertices(context)
        if len(points) < 4:
            raise OperatorError(f"Select at least 4 vertices that enclose a volume ({len(points)} selected)")
        try:
            rotation, center, semi_axes = fit_ellipsoid(points, self.mode, surface=rest)
        except ValueError as error:
            raise OperatorError(f"Cannot fit an ellipsoid: {error}") from error
        traces = selected_traces(context, self.mode)  # after edit_mesh_world_vertices updated the meshes
        obj, collection, error = add_part(self, context, rotation, center, semi_axes)
        if error:
            raise OperatorError(error)
        recorded = "recorded"
        if len(traces) == 1:
            write_trace(obj, traces[0])
        else:  # a part traced across meshes cannot be fitted again on other bodies of one mesh
            recorded = f"not recorded: the selection spans {len(traces)} meshes"
        self.report(
            {"INFO"},
            f"Fitted '{obj.ellimann.part_name}' ({self.mode}) to {len(points)} vertices in "
            f"'{collection.name}' (selection {recorded})",
        )
        return {"FINISHED"}


classes = (ELLIMANN_OT_new_mannequin, ELLIMANN_OT_add_ellipsoid, ELLIMANN_OT_fit_ellipsoid)
