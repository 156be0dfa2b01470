"""Write mannequins to .blend, .glb and .obj, atomically (headless CLI and scripts).

Blender files are written from an empty scene holding only that mannequin (and its cushions when
asked), to a temporary file in the target folder that is renamed into place once complete
(:func:`atomic.atomic_output`). A .glb goes through :func:`export.export_gltf`, so it always
carries ElliMann's extras. JSON and MJCF come from the core (:func:`core.writers.write_core_file`)
and need no scene.
"""

import os

import bpy

from ..core.cushion import DEFAULT_SUBDIVISIONS
from ..core.errors import ElliMannError
from ..core.files import atomic_output
from ..core.formats import BLENDER_FORMATS
from .chatter import blender_output
from .convert import mannequin_to_collection, objects_recursive, write_measured
from .cushions import build_cushions
from .export import export_gltf

LIVE_SUBDIVISIONS = 3


def empty_scene():
    """Start from an empty file (add-ons stay registered)."""
    with blender_output():
        bpy.ops.wm.read_homefile(use_empty=True)
    return bpy.context.scene


def shown_objects(collection):
    """What a file shows: cushions where there are any, ellipsoids for every part without a cushion."""
    objects = objects_recursive(collection)
    has_cushions = any(o.ellimann.kind == "CUSHION" for o in objects)
    return [o for o in objects if o.ellimann.is_part and (
        o.ellimann.kind == "CUSHION" or (o.ellimann.kind == "ELLIPSOID" and not (has_cushions and o.ellimann.partner)))]


def add_mannequin(mannequin, measured=None, cushions=False):
    """The mannequin as a new collection in the current scene; with cushions, the paired ellipsoids are hidden."""
    collection = mannequin_to_collection(mannequin)
    if measured is not None:
        write_measured(collection, measured)
    if cushions:
        _add_cushions(collection)
    return collection


def _add_cushions(collection, subdivisions=DEFAULT_SUBDIVISIONS, view_layer=None):
    """Build the cushions and hide the ellipsoids they replace in ``view_layer`` (default: the context's).

    Checked before anything changes: every ellipsoid to hide is in ``view_layer`` (ElliMannError otherwise),
    so a failure leaves neither new cushions with their ellipsoids shown nor half the ellipsoids hidden.
    """
    view_layer = view_layer or bpy.context.view_layer
    # Hidden in the view layer, not disabled (hide_viewport): Blender does not evaluate disabled
    # objects, so after reopening the file their matrix_world would be the identity.
    view_layer.update()  # new objects get their view-layer bases (hide_set needs them)
    replaced = [o for o in objects_recursive(collection)
                if o.ellimann.is_part and o.ellimann.kind == "ELLIPSOID" and o.ellimann.partner]
    missing = [o.name for o in replaced if view_layer.objects.get(o.name) != o]
    if missing:
        raise ElliMannError(f"cannot hide '{missing[0]}' of '{collection.name}': it is not in view layer "
                            f"'{view_layer.name}' (include the mannequin there to build its cushions)")
    build_cushions(collection, subdivisions)
    for obj in replaced:
        obj.hide_set(True, view_layer=view_layer)
        obj.hide_render = True


def refresh_cushions(collection, subdivisions=LIVE_SUBDIVISIONS, view_layer=None):
    """Rebuild a mannequin's cushions after its ellipsoids moved (replaces only the cushions ElliMann built).

    Live updates call it rarely: while a slider is dragged they move the cushions in place
    (``synthesize.move_cushions``), and rebuild them here only once the fields are still
    (``synthesize.settle_live``) or when the cushions cannot be moved (one is missing). They rebuild at
    ``subdivisions`` = LIVE_SUBDIVISIONS (642 vertices), or the cushions' own level if coarser, since
    a rebuild at Synthesize's 2,562 takes seconds; Synthesize builds them at full resolution.

    The ellipsoids they replace are hidden in ``view_layer`` (default: the context's; a timer passes the
    view layer of the scene it works on). Raises ElliMannError, changing nothing, if they are not in it.
    """
    _add_cushions(collection, subdivisions, view_layer)


def write_mannequin(mannequin, paths, measured=None, cushions=False):
    """Write one mannequin to every .blend, .glb and .obj in ``paths`` (format from the extension), all
    from one empty scene. Returns the paths. (.json and MJCF need no Blender: ``core.writers``.)

    ``cushions``: the files show the cushions instead of the ellipsoids they replace. A path of another
    kind raises ElliMannError before anything is written; an OSError names the file that failed
    (``filename``, as given in ``paths``).
    """
    paths = [os.fspath(p) for p in paths]
    other = [p for p in paths if extension(p) not in BLENDER_FORMATS]
    if other:
        raise ElliMannError(f"path: {other[0]!r} is not a .blend, .glb or .obj file")
    if paths:
        empty_scene()
        collection = add_mannequin(mannequin, measured, cushions)
        for path in paths:
            _write_blender_file(path, collection)
    return paths


def extension(path):
    return os.path.splitext(os.fspath(path))[1].lower().lstrip(".")


def _write_blender_file(path, collection):
    kind = extension(path)
    if kind == "glb":  # atomic itself; leaves out what renders do not show (ellipsoids a cushion replaces)
        with blender_output():
            export_gltf(collection, path)
        return
    with atomic_output(path) as temp, blender_output():
        if kind == "blend":
            bpy.ops.wm.save_as_mainfile(filepath=temp, copy=True, check_existing=False)
        else:
            _select_only(shown_objects(collection))
            bpy.ops.wm.obj_export(filepath=temp, export_selected_objects=True, export_materials=False,
                                  check_existing=False)


def _select_only(objects):
    bpy.context.view_layer.update()  # give newly linked objects their view-layer bases before selecting
    for obj in bpy.context.view_layer.objects:
        obj.select_set(False)
    for obj in objects:
        obj.select_set(True)
