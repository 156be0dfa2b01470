"""Small helpers shared by the operators: reporting problems and picking what to work on."""

from bpy.props import EnumProperty

from ..convert import ellipsoid_objects
from ..selection import active_mannequin, selected_ellipsoids

SCOPE_ITEMS = (
    ("SELECTED", "Selected", "The selected ellipsoids"),
    ("MANNEQUIN", "Mannequin", "Every ellipsoid of the active mannequin"),
)


def scope_property(default="SELECTED"):
    return EnumProperty(name="Apply To", items=SCOPE_ITEMS, default=default,
                        description="Work on the selected ellipsoids or on the whole active mannequin")


def targets(context, scope):
    """Ellipsoid objects an operator with a scope works on."""
    if scope == "SELECTED":
        return selected_ellipsoids(context)
    collection = active_mannequin(context)
    return ellipsoid_objects(collection) if collection is not None else []


def has_targets(context):
    """Poll for scoped operators: something selected or an active mannequin."""
    return bool(selected_ellipsoids(context)) or active_mannequin(context) is not None


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


def plural(count, word):
    return f"{count} {word}{'' if count == 1 else 's'}"
