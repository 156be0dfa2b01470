"""Build Reference Set: the core builder (core/fitting/reference_build.py) on the chosen Base Mannequin and bodies.

Clicked (invoke), the build runs on a worker thread (pure numpy, no Blender data touched) while a modal
timer shows its progress and Esc cancels it; run from a script (execute), it runs in place with Blender's
progress indicator. Everything is read and checked first: a refused build changes nothing. The result
is written as a reference-set folder and loaded into a new collection of new mannequin collections.
"""

import pathlib
import re
import threading

import bpy
from bpy.props import IntProperty

from ....core.errors import ElliMannError, MannequinError
from ....core.fitting.reference_build import (
    BASE_STEM,
    BuildCancelledError,
    build_reference_set,
    traced_mesh,
    validate_inputs,
)
from ....core.measurements import MEASUREMENTS
from ....core.synthesis.bodies import shipped_topology_labels
from ....core.synthesis.manifest import MANIFEST_FILE
from ... import ids
from ...bridge.bodies import body_mesh
from ...bridge.convert import collection_to_mannequin, mannequin_to_collection, new_collection
from ..base import ElliMannOperator, OperatorError, cancel

TIMER_SECONDS = 0.25


def stem_of(name):
    """A file stem for an object's name: letters, digits, _ . - (anything else becomes _)."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name).lstrip("._-") or "body"


class Request:
    """Everything a build needs, read from the scene and checked before any work (OperatorError if not)."""

    def __init__(self, context):
        props = context.scene.ellimann_references
        if props.base is None:
            raise OperatorError("Choose the Base Mannequin (a traced mannequin collection)")
        try:
            self.base = collection_to_mannequin(props.base)
        except MannequinError as error:
            raise OperatorError(f"Fix '{props.base.name}' first", error.problems) from error
        rows = [row for row in props.bodies if row.body is not None]
        self.bodies = [body_mesh(row.body, stem_of(row.body.name)) for row in rows]
        self.targets = {
            body.name: dict(zip(MEASUREMENTS, map(float, row.target))) for body, row in zip(self.bodies, rows)
        }
        if not props.folder.strip():
            raise OperatorError("Choose the folder the reference set is written to")
        self.folder = pathlib.Path(bpy.path.abspath(props.folder))
        if self.folder.exists() and (
            not self.folder.is_dir() or (any(self.folder.iterdir()) and not (self.folder / MANIFEST_FILE).is_file())
        ):
            raise OperatorError(
                f"{self.folder} is a file or a folder of other files: choose a new or empty folder "
                "(or one holding a reference set to replace)"
            )
        if BASE_STEM in self.targets:
            raise OperatorError(f"A body may not be named '{BASE_STEM}' (the base's file in the set)")
        try:
            validate_inputs(self.base, self.bodies, self.targets)
        except ElliMannError as error:
            raise OperatorError(f"Cannot build: {error}") from error
        self.name = props.set_name.strip() or self.folder.name
        self.sex = None if props.sex == "NONE" else props.sex

    def build(self, progress=None, cancel_flag=None):
        return build_reference_set(
            self.base,
            self.bodies,
            self.targets,
            progress=progress,
            cancel=cancel_flag,
            name=self.name,
            sex=self.sex,
            base_stem=BASE_STEM,
            body_labels=shipped_topology_labels(self.bodies[0].faces),  # the body model's bodies: kept for its skin
            provenance={
                "built_by": "Blender: ElliMann > Build Reference Set",
                "base": {"collection": self.base.name, **traced_mesh(self.base)},
                "bodies": {body.name: {"object": body.name} for body in self.bodies},
            },
        )


def finish(operator, context, request, built):
    """Write the set (a core BuiltReferenceSet) and load it into a new collection (one child collection per RM);
    report the outcome."""
    rms, report, manifest = built.mannequins, built.report, built.manifest
    try:
        built.write(request.folder)
    except OSError as error:
        return cancel(operator, f"Cannot write the reference set to {request.folder}: {error}")
    parent = new_collection(f"{manifest.name} (reference set)")
    for stem, rm in rms.items():
        mannequin_to_collection(rm, name=rm.name or stem, parent=parent)
    worst = max((abs(report.worst(stem)[1]), stem) for stem in rms)
    filled = min(report.fill[stem]["ellipsoids"]["coverage"] for stem in rms) if report.fill else None
    props = context.scene.ellimann_references
    props.status = f"{len(rms)} RMs in {request.folder}; worst m_T error {worst[0]:.3%} ({worst[1]})" + (
        f"; each fills at least {filled:.0%} of its body" if filled is not None else ""
    )
    if built.bodies is not None:
        props.status += "; the bodies kept for the body skin"

    props.progress = 1.0
    operator.report({"INFO"}, f"Built '{manifest.name}': {props.status}; use it in Synthesize > Reference Set > Folder")
    return {"FINISHED"}


class ELLIMANN_OT_build_reference_set(ElliMannOperator, bpy.types.Operator):
    """Fit the base's traced parts in each body, refine them to their targets and save a reference set (Esc cancels)"""

    bl_idname = ids.BUILD_REFERENCE_SET
    bl_label = "Build Reference Set"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        props = getattr(context.scene, "ellimann_references", None)
        return context.mode == "OBJECT" and props is not None and props.base is not None and len(props.bodies) >= 3

    def run(self, context):
        request = Request(context)
        window_manager = context.window_manager
        window_manager.progress_begin(0, 100)
        try:
            built = request.build(progress=lambda fraction, _text: window_manager.progress_update(int(100 * fraction)))
        except ElliMannError as error:
            raise OperatorError(f"Cannot build: {error}") from error
        finally:
            window_manager.progress_end()
        return finish(self, context, request, built)

    def invoke(self, context, event):
        try:
            self._request = Request(context)
        except OperatorError as refusal:
            return cancel(self, refusal.message, refusal.problems)
        self._stop = threading.Event()
        self._state = {"progress": 0.0, "text": "starting", "result": None, "error": None}
        self._thread = threading.Thread(target=self._work, daemon=True)
        self._thread.start()
        self._timer = context.window_manager.event_timer_add(TIMER_SECONDS, window=context.window)
        context.window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def _work(self):  # the worker thread: core only, no bpy
        def progress(fraction, text):
            self._state.update(progress=fraction, text=text)

        try:
            self._state["result"] = self._request.build(progress, self._stop.is_set)
        except (ElliMannError, BuildCancelledError) as error:
            self._state["error"] = error

    def modal(self, context, event):
        if event.type == "ESC":
            self._stop.set()  # the worker stops at the next part
            return {"RUNNING_MODAL"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        props = context.scene.ellimann_references
        if self._thread.is_alive():
            props.progress, props.status = self._state["progress"], self._state["text"]
            for area in context.screen.areas if context.screen else ():
                area.tag_redraw()
            return {"RUNNING_MODAL"}
        context.window_manager.event_timer_remove(self._timer)
        error = self._state["error"]
        if isinstance(error, BuildCancelledError):
            props.status = "cancelled: nothing was written"
            self.report({"WARNING"}, "Build Reference Set cancelled: nothing was written")
            return {"CANCELLED"}
        if error is not None:
            props.status = f"failed: {error}"
            return cancel(self, f"Cannot build: {error}")
        return finish(self, context, self._request, self._state["result"])


class ELLIMANN_OT_add_reference_bodies(ElliMannOperator, bpy.types.Operator):
    """Add the selected mesh objects as bodies of the reference set (each with the default targets to edit)"""

    bl_idname = ids.ADD_REFERENCE_BODIES
    bl_label = "Add Selected Bodies"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return hasattr(context.scene, "ellimann_references") and any(
            o.type == "MESH" and not o.ellimann.is_part for o in context.selected_objects
        )

    def run(self, context):
        props = context.scene.ellimann_references
        present = {row.body for row in props.bodies}
        added = 0
        for obj in sorted(context.selected_objects, key=lambda o: o.name):
            if obj.type == "MESH" and not obj.ellimann.is_part and obj not in present:
                props.bodies.add().body = obj
                added += 1
        self.report({"INFO"}, f"Added {added} bodies ({len(props.bodies)} in the set)")
        return {"FINISHED"}


class ELLIMANN_OT_remove_reference_body(ElliMannOperator, bpy.types.Operator):
    """Remove this body from the reference set (the object itself is kept)"""

    bl_idname = ids.REMOVE_REFERENCE_BODY
    bl_label = "Remove Body"
    bl_options = {"REGISTER", "UNDO"}

    index: IntProperty(name="Row", default=0, min=0, description="Which body row to remove")

    @classmethod
    def poll(cls, context):
        props = getattr(context.scene, "ellimann_references", None)
        return props is not None and len(props.bodies) > 0

    def run(self, context):
        props = context.scene.ellimann_references
        if self.index >= len(props.bodies):
            raise OperatorError(f"There is no body row {self.index + 1} ({len(props.bodies)} rows)")
        props.bodies.remove(self.index)
        return {"FINISHED"}


classes = (ELLIMANN_OT_build_reference_set, ELLIMANN_OT_add_reference_bodies, ELLIMANN_OT_remove_reference_body)
