"""Every file Blender writes for ElliMann (.blend, .glb, .png), put in place atomically (the core writes .obj).

Two parts, one module: the glTF export with ElliMann's extras (``export_gltf``) and
``write_mannequin``, which writes one mannequin to .blend and .glb from an empty scene (the
CLI's and scripts' writer). Every write goes through the one atomic writer,
``core.files.atomic_output`` (JSON and MJCF through ``core.files`` too), so a failed write never
leaves a half-written file and every format gets the same permissions.

Writing mannequins: Blender files are written from an empty scene holding only that mannequin (and
its cushions when asked), to a temporary file in the target folder that is renamed into place once
complete (:func:`atomic_output`). A .glb goes through :func:`export_gltf`, so it always carries
ElliMann's extras.

glTF export: glTF export of a mannequin collection that keeps piece names and measurements (as glTF ``extras``).

Blender's glTF exporter, asked for one collection (``collection=``, Blender 4.2+) with
``export_extras=True``, writes each object's custom properties as its node's ``extras`` and the
collection's as the glTF scene's ``extras``. ElliMann's own data lives in a registered property
group named ``ellimann``, which Blender 5.0+ keeps apart from custom properties but 4.x stores as the
custom property of that name (and refuses to have replaced by a dict). So the export leaves the
objects alone and writes ``extras.ellimann`` into the written file's JSON chunk afterwards, the same
on every Blender; the user's own custom properties still travel as the exporter writes them.

What a three.js / game-engine user finds in the .glb:
- one node per piece, named after the part (``"7.a Thigh.L"``); ellipsoids share one unit-sphere
  mesh, so the node's translation/rotation/scale *is* the ellipsoid (in glTF's Y-up axes);
  ``node.extras.ellimann`` = {part, kind, side, region, girth, depends, partner} and, for
  ellipsoids, the frame in ElliMann's Z-up axes: center_m, axes (the three local axes as rows),
  semi_axes_m;
- ``scene.extras.ellimann`` = {format, version, name, role, units, up, target_cm, measured_cm}
  (target_cm only when the mannequin has a target; measured_cm is m_T of the ellipsoids).

A mannequin with an armature (``services.rig``) is a skinned glTF: one joint node per bone (SMPL names),
every piece a skinned mesh weighted fully to its bone (the exporter writes each piece's vertices at rest
in the armature's space, so such a node carries no transform of its own; ``extras.ellimann`` still
gives its rest frame), the armature in its current pose, and its action (the walk) as an animation.

With a skin (``services.skin``), the skin is one more skinned mesh (``extras.ellimann``: kind SKIN and how it was
made), weighted smoothly to the bones (up to four per vertex); the pieces stay beside it, inside it, as colliders.
In a .blend the pieces are hidden with a Collision modifier each.
"""

import json
import os
import struct

import bpy
import numpy as np

from ...core.errors import ElliMannError
from ...core.files import atomic_output
from ...core.formats.glb import EXTRAS_FORMAT, EXTRAS_KEY, EXTRAS_VERSION
from ...core.formats.table import SCENE_FORMATS, extension_of
from ...core.measurements import MEASUREMENTS
from ..bridge.built import built_objects, is_stale
from ..bridge.convert import collection_to_mannequin, objects_recursive
from ..bridge.selection import part_lookup
from ..bridge.skin import is_stale_skin, skin_object, skin_record_of
from .chatter import blender_output
from .rig import build_rig
from .scene import add_mannequin, empty_scene
from .skin import add_skin, pieces_as_colliders

# ------------------------------------------------------------------------------------------------ glTF


def part_extras(obj):
    """The node extras of one ElliMann object (ellipsoid or cushion)."""
    props = obj.ellimann
    extras = {
        "part": props.part_name,
        "kind": props.kind,
        "side": props.side,
        "region": props.region,
        "girth": bool(props.girth),
        "depends": [m for m in MEASUREMENTS if m in props.depends],
        "partner": props.partner,
    }
    if props.kind == "SKIN":
        return {"kind": "SKIN", "skin": skin_record_of(obj)}
    if props.kind == "ELLIPSOID":
        matrix = np.array(obj.matrix_world)
        semi = np.linalg.norm(matrix[:3, :3], axis=0)
        extras.update(
            center_m=matrix[:3, 3].tolist(), axes=(matrix[:3, :3] / semi).T.tolist(), semi_axes_m=semi.tolist()
        )
    return extras


def scene_extras(mannequin, measured=None):
    """The scene extras of ``mannequin``; ``measured``: its m_T ({key: cm}) if the caller holds it (else taken)."""
    out = {
        "format": EXTRAS_FORMAT,
        "version": EXTRAS_VERSION,
        "name": mannequin.name,
        "role": mannequin.role,
        "units": "m (geometry), cm (measurements)",
        "up": "ElliMann data is Z-up, facing -Y; glTF nodes are Y-up as glTF requires",
        "measured_cm": {k: float(measured[k]) for k in MEASUREMENTS} if measured is not None else mannequin.measure(),
    }
    if mannequin.measurements:
        out["target_cm"] = {k: float(v) for k, v in mannequin.measurements.items()}
    return out


def export_gltf(collection, path, mannequin=None, measured=None):
    """Write a mannequin collection (and its child collections) to a binary glTF (.glb), atomically
    (:func:`atomic_output`, like every file Blender writes for ElliMann).

    Objects hidden from renders are left out: in a mannequin shown with cushions those are the
    ellipsoids the cushions replace, so the file holds each convex piece once.

    Raises ElliMannError for a path not ending in .glb or for built cushions that are out of date
    (their ellipsoids moved since they were built: a live update, an undo or a reload can leave them
    so), and MannequinError (naming the parts) for a collection that is not a valid mannequin;
    nothing is written then, and the file is unchanged. Returns the path.

    ``mannequin`` (and its m_T ``measured``, {key: cm}): the core mannequin the collection was just made from
    (``write_mannequin``): its extras are written from it, without reading the collection back or measuring
    again; without it (the export operator) the collection is read and checked.
    """
    path = os.fspath(path)
    if not path.lower().endswith(".glb"):
        raise ElliMannError(f"path: a glTF export is written as binary glTF and must end in .glb, got {path!r}")
    bpy.context.view_layer.update()  # matrix_world of objects a script just moved
    if mannequin is None:
        mannequin = collection_to_mannequin(collection)
        parts = part_lookup(collection)
        stale = [c.name for c in built_objects(collection, "CUSHION") if is_stale(c, parts)]
        skin = skin_object(collection)
        if skin is not None and is_stale_skin(skin, mannequin):
            raise ElliMannError(
                f"the skin of '{collection.name}' is out of date (its pieces moved since it was built): "
                "Build Skin first"
            )
    else:
        stale = []  # its cushions and skin were built from the mannequin a moment ago
    if stale:
        more = f" and {len(stale) - 1} more" if len(stale) > 1 else ""
        raise ElliMannError(
            f"the cushions of '{collection.name}' are out of date ('{stale[0]}'{more}: their "
            "ellipsoids moved since they were built): Build Cushions first"
        )
    objects = [o for o in objects_recursive(collection) if o.ellimann.is_part]
    node_extras = {o.name: part_extras(o) for o in objects}
    with atomic_output(path) as temp:
        # Skins and animations are the exporter's defaults; the armature's node transforms are its current
        # pose rather than its rest (a posed mannequin shows posed; an action plays the same either way).
        result = bpy.ops.export_scene.gltf(
            filepath=temp,
            export_format="GLB",
            export_extras=True,
            collection=collection.name,
            export_yup=True,
            use_renderable=True,
            export_rest_position_armature=False,
        )
        if result != {"FINISHED"}:
            raise ElliMannError(f"path: Blender's glTF exporter did not finish ({result})")
        _set_extras(temp, node_extras, scene_extras(mannequin, measured))
    return path


def _set_extras(path, node_extras, scene_extras_):
    """Put ``extras.ellimann`` on the scene of a .glb file and on each of its nodes named in ``node_extras``
    (the exporter leaves out what is hidden from renders: those objects have no node to carry it)."""
    with open(path, "rb") as stream:
        data = stream.read()
    doc, rest = _split_glb(data, path)
    for node in doc.get("nodes", []):
        if node.get("name") in node_extras:
            node.setdefault("extras", {})[EXTRAS_KEY] = node_extras[node["name"]]
    for scene in doc.get("scenes", []):
        scene.setdefault("extras", {})[EXTRAS_KEY] = scene_extras_
    chunk = json.dumps(doc, separators=(",", ":"), allow_nan=False).encode()
    chunk += b" " * (-len(chunk) % 4)  # chunks are 4-byte aligned; glTF pads JSON with spaces
    header = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(chunk) + len(rest))
    with open(path, "wb") as stream:
        stream.write(header + struct.pack("<I4s", len(chunk), b"JSON") + chunk + rest)


def _split_glb(data, path):
    """(the JSON chunk as a dict, every chunk after it as bytes) of a .glb file's bytes."""
    if len(data) < 20:
        raise ElliMannError(f"path: {path} is not a binary glTF file")
    magic, _, total = struct.unpack_from("<4sII", data)
    length, kind = struct.unpack_from("<I4s", data, 12)
    if magic != b"glTF" or kind != b"JSON" or total != len(data) or 20 + length > len(data):
        raise ElliMannError(f"path: {path} is not a whole binary glTF file")
    return json.loads(data[20 : 20 + length]), data[20 + length :]


# ------------------------------------------------------------------------------------------------ mannequin files


def write_mannequin(mannequin, paths, measured=None, cushions=False, skin=None):
    """Write one mannequin to every .blend and .glb in ``paths`` (format from the extension), all
    from one empty scene. Returns the paths. (.obj, .json and MJCF need no Blender: ``core.formats.core_writers``;
    a posed mannequin: ``services.posing``.)

    ``cushions``: the files show the cushions instead of the ellipsoids they replace. ``skin``: the mannequin's
    core Skin (``core.skin.surface``), written beside the pieces (:func:`write_with_skin`). A path of another
    kind raises ElliMannError before anything is written; an OSError names the file that failed
    (``filename``, as given in ``paths``).
    """
    paths = checked_paths(paths)
    if paths:
        empty_scene()
        collection = add_mannequin(mannequin, measured, cushions)
        if skin is not None and mannequin.joints is not None:
            build_rig(collection, mannequin)  # the skin is bound to the bones: posable in Blender
        write_with_skin(paths, collection, mannequin, measured, skin)
    return paths


def write_with_skin(paths, collection, mannequin, measured=None, skin=None):
    """Write the scene holding ``collection`` to each path; with ``skin`` (a core Skin of ``mannequin``), the skin
    object is added first (bound to the armature if there is one), the .glb files are written with the pieces as
    they are (nodes inside the skin), then the pieces are hidden as colliders for the .blend files."""
    if skin is not None:
        add_skin(collection, skin)
        paths = sorted(paths, key=lambda path: extension_of(path) != "glb")
    for path in paths:
        if skin is not None and extension_of(path) == "blend":
            pieces_as_colliders(collection, hidden=True)
        write_blender_file(path, collection, mannequin, measured)


def checked_paths(paths):
    """``paths`` as strings; ElliMannError naming the first that is not a .blend or .glb file."""
    paths = [os.fspath(p) for p in paths]
    other = [p for p in paths if extension_of(p) not in SCENE_FORMATS]
    if other:
        raise ElliMannError(f"path: {other[0]!r} is not a .blend or .glb file (the core writes .obj, .json, .xml)")
    return paths


def write_blender_file(path, collection, mannequin=None, measured=None):
    """Write the scene holding ``collection`` to ``path`` (.blend or .glb by its extension), atomically;
    ``mannequin`` and ``measured``: what the collection was made from, for the .glb's extras (:func:`export_gltf`)."""
    kind = extension_of(path)
    if kind == "glb":  # atomic itself; leaves out what renders do not show (ellipsoids a cushion replaces)
        with blender_output():
            export_gltf(collection, path, mannequin, measured)
        return
    with atomic_output(path) as temp, blender_output():
        bpy.ops.wm.save_as_mainfile(filepath=temp, copy=True, check_existing=False)
