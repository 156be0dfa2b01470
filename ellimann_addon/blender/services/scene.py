"""Mannequins in the current scene: an empty file, a mannequin as a new collection (with cushions, the
ellipsoids they replace hidden), and rebuilding those cushions after the ellipsoids moved.

Used by the Synthesize feature (live updates), the CLI, the render service and the file writers
(:mod:`.files`).
"""

import bpy

from ...core.constants import CUSHION_LEVEL, LIVE_CUSHION_LEVEL
from ...core.errors import ElliMannError
from ..bridge.convert import mannequin_to_collection, objects_recursive, write_measured
from .chatter import blender_output
from .cushions import build_cushions


def empty_scene():
    """Start from an empty file (add-ons stay registered)."""
    with blender_output():
        bpy.ops.wm.read_homefile(use_empty=True)
    return bpy.context.scene


def add_mannequin(mannequin, measured=None, cushions=False):
    """The mannequin as a new collection in the current scene; with cushions, the paired ellipsoids are hidden."""
    collection = mannequin_to_collection(mannequin)
    if measured is not None:
        write_measured(collection, measured)
    if cushions:
        _add_cushions(collection, mannequin=mannequin)
    return collection


def _add_cushions(collection, subdivisions=CUSHION_LEVEL, view_layer=None, mannequin=None):
    """Build the cushions and hide the ellipsoids they replace in ``view_layer`` (default: the context's).

    Checked before anything changes: every ellipsoid to hide is in ``view_layer`` (ElliMannError otherwise),
    so a failure leaves neither new cushions with their ellipsoids shown nor half the ellipsoids hidden.
    ``mannequin``: the core mannequin the collection holds, if the caller has it (see :func:`build_cushions`).
    """
    view_layer = view_layer or bpy.context.view_layer
    # Hidden in the view layer, not disabled (hide_viewport): Blender does not evaluate disabled
    # objects, so after reopening the file their matrix_world would be the identity.
    view_layer.update()  # new objects get their view-layer bases (hide_set needs them)
    replaced = [
        o
        for o in objects_recursive(collection)
        if o.ellimann.is_part and o.ellimann.kind == "ELLIPSOID" and o.ellimann.partner
    ]
    missing = [o.name for o in replaced if view_layer.objects.get(o.name) != o]
    if missing:
        raise ElliMannError(
            f"cannot hide '{missing[0]}' of '{collection.name}': it is not in view layer "
            f"'{view_layer.name}' (include the mannequin there to build its cushions)"
        )
    build_cushions(collection, subdivisions, mannequin=mannequin)
    for obj in replaced:
        obj.hide_set(True, view_layer=view_layer)
        obj.hide_render = True


def refresh_cushions(collection, subdivisions=LIVE_CUSHION_LEVEL, view_layer=None):
    """Rebuild a mannequin's cushions after its ellipsoids moved (replaces only the cushions ElliMann built).

    Live updates call it rarely: while a slider is dragged they move the cushions in place
    (``features.synthesize.live.move_cushions``), and rebuild them here only once the fields are still
    (``features.synthesize.live.settle_live``) or when the cushions cannot be moved (one is missing). They rebuild at
    ``subdivisions`` = LIVE_CUSHION_LEVEL (642 vertices), or the cushions' own level if coarser, since
    a rebuild at Synthesize's 2,562 takes seconds; Synthesize builds them at full resolution.

    The ellipsoids they replace are hidden in ``view_layer`` (default: the context's; a timer passes the
    view layer of the scene it works on). Raises ElliMannError, changing nothing, if they are not in it.
    """
    _add_cushions(collection, subdivisions, view_layer)
