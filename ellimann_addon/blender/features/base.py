"""What every feature shares: the operator bases (the active-mannequin poll and lookup, and the report of
a refusal), the sidebar panel bases, and small helpers for scoped operators and messages.

An operator's ``run`` raises :class:`OperatorError` to refuse; the base reports it (:func:`cancel`) and
returns CANCELLED, so no operator repeats the ``try``/``report``/``return`` opening.
"""

import contextlib

from bpy.props import EnumProperty

from ...core.errors import MannequinError
from .. import ids
from ..bridge.convert import collection_to_mannequin, ellipsoid_objects, read_frames
from ..bridge.selection import active_mannequin, selected_ellipsoids

CATEGORY = "ElliMann"
FIX_FRAMES_FIRST = "Fix these ellipsoids first (Fix Frames)"

SCOPE_ITEMS = (
    ("SELECTED", "Selected", "The selected ellipsoids"),
    ("MANNEQUIN", "Mannequin", "Every ellipsoid of the active mannequin"),
)


# ------------------------------------------------------------------------------------------------ operators


class OperatorError(Exception):
    """Raised inside an operator's ``run``: report ``message`` (and each of ``problems``) and cancel."""

    def __init__(self, message, problems=()):
        super().__init__(message)
        self.message = message
        self.problems = problems


class ElliMannOperator:
    """Mixin before ``bpy.types.Operator``: ``execute`` runs ``self.run(context)`` and turns a
    :class:`OperatorError` into the reports and CANCELLED (nothing was changed)."""

    def execute(self, context):
        try:
            return self.run(context)
        except OperatorError as refusal:
            return cancel(self, refusal.message, refusal.problems)

    def run(self, context):
        raise NotImplementedError


class MannequinOperator(ElliMannOperator):
    """Mixin for operators on the active mannequin (``bridge.selection.active_mannequin``).

    ``poll``: there is an active mannequin (and Blender is in Object Mode unless ``OBJECT_MODE_ONLY``
    is False). ``execute`` looks it up and calls ``self.run(context, collection)``.
    """

    OBJECT_MODE_ONLY = True

    @classmethod
    def poll(cls, context):
        return has_mannequin(context, cls.OBJECT_MODE_ONLY)

    def execute(self, context):
        collection = active_mannequin(context)
        try:
            return self.run(context, collection)
        except OperatorError as refusal:
            return cancel(self, refusal.message, refusal.problems)

    def run(self, context, collection):
        raise NotImplementedError


def has_mannequin(context, object_mode_only=True):
    """MannequinOperator's poll: an active mannequin (in Object Mode, unless ``object_mode_only`` is False).
    An operator whose poll adds a condition calls this."""
    return (not object_mode_only or context.mode == "OBJECT") and active_mannequin(context) is not None


@contextlib.contextmanager
def fix_first(collection):
    """Inside the block, a MannequinError (the collection is not a valid mannequin) becomes
    ``OperatorError("Fix '<name>' first", its problems)``."""
    try:
        yield
    except MannequinError as error:
        raise OperatorError(f"Fix '{collection.name}' first", error.problems) from error


def mannequin_or_cancel(collection):
    """The collection as a core Mannequin, or OperatorError("Fix '<name>' first") naming every problem."""
    with fix_first(collection):
        return collection_to_mannequin(collection)


def frames_or_cancel(objects):
    """(rotation, center, semi_axes) of ellipsoid objects, else OperatorError(FIX_FRAMES_FIRST, the problems)."""
    try:
        return read_frames(objects)
    except MannequinError as error:
        raise OperatorError(FIX_FRAMES_FIRST, error.problems) from error


def cancel(operator, message, problems=()):
    """Report each problem as a warning, then the error with the first problem (the status bar shows only
    the last report); return CANCELLED: nothing was changed."""
    problems = [str(p) for p in problems]
    for problem in problems:
        operator.report({"WARNING"}, problem)
    if problems:
        more = f" (and {len(problems) - 1} more in the Info log)" if len(problems) > 1 else ""
        message = f"{message}: {problems[0]}{more}"
    operator.report({"ERROR"}, message)
    return {"CANCELLED"}


def scope_property(default="SELECTED"):
    return EnumProperty(
        name="Apply To",
        items=SCOPE_ITEMS,
        default=default,
        description="Work on the selected ellipsoids or on the whole active mannequin",
    )


class ScopedOperator(ElliMannOperator):
    """Mixin for operators with a ``scope`` (``scope_property``): the selected ellipsoids or the whole active
    mannequin. ``poll``: Object Mode and something to work on; :meth:`targets`: the ellipsoids in scope."""

    @classmethod
    def poll(cls, context):
        has_targets = bool(selected_ellipsoids(context)) or active_mannequin(context) is not None
        return context.mode == "OBJECT" and has_targets

    def targets(self, context):
        if self.scope == "SELECTED":
            return selected_ellipsoids(context)
        collection = active_mannequin(context)
        return ellipsoid_objects(collection) if collection is not None else []


def plural(count, word):
    return f"{count} {word}{'' if count == 1 else 's'}"


# ------------------------------------------------------------------------------------------------ panels


class ElliMannPanel:
    """One base for every ElliMann sidebar panel (3D viewport > sidebar > ElliMann tab)."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = CATEGORY


class SubPanel(ElliMannPanel):
    """A sub-panel of the main ElliMann panel; set ``bl_order`` from ``ids``."""

    bl_parent_id = ids.PANEL_MAIN
