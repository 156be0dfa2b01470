"""glTF export of a mannequin collection that keeps piece names and measurements (as glTF ``extras``).

Blender's glTF exporter, asked for one collection (``collection=``, Blender 4.2+) with
``export_extras=True``, writes each object's custom properties as its node's ``extras`` and the
collection's as the glTF scene's ``extras``. ElliMann's own data lives in registered property
groups, which the exporter does not see, so for the export it copies them into plain custom
properties named ``ellimann`` and removes them again afterwards (prior values are restored).

What a three.js / game-engine user finds in the .glb:
- one node per piece, named after the part (``"7.a Thigh.L"``); ellipsoids share one unit-sphere
  mesh, so the node's translation/rotation/scale *is* the ellipsoid (in glTF's Y-up axes);
  ``node.extras.ellimann`` = {part, kind, side, region, girth, depends, partner} and, for
  ellipsoids, the frame in ElliMann's Z-up axes: center_m, axes (the three local axes as rows),
  semi_axes_m;
- ``scene.extras.ellimann`` = {format, version, name, role, units, up, target_cm, measured_cm}
  (target_cm only when the mannequin has a target; measured_cm is m_T of the ellipsoids).
"""

import json
import os
import struct

import bpy
import numpy as np

from ..core.constants import MEASUREMENTS
from ..core.errors import ElliMannError
from .atomic import atomic_output
from .built import built_objects, is_stale
from .convert import collection_to_mannequin, objects_recursive
from .selection import part_lookup

EXTRAS_KEY = "ellimann"
EXTRAS_FORMAT = "ellimann.gltf-extras"
EXTRAS_VERSION = 1


def part_extras(obj):
    """The node extras of one ElliMann object (ellipsoid or cushion)."""
    props = obj.ellimann
    extras = {"part": props.part_name, "kind": props.kind, "side": props.side, "region": props.region,
              "girth": bool(props.girth), "depends": [m for m in MEASUREMENTS if m in props.depends],
              "partner": props.partner}
    if props.kind == "ELLIPSOID":
        matrix = np.array(obj.matrix_world)
        semi = np.linalg.norm(matrix[:3, :3], axis=0)
        extras.update(center_m=matrix[:3, 3].tolist(), axes=(matrix[:3, :3] / semi).T.tolist(),
                      semi_axes_m=semi.tolist())
    return extras


def scene_extras(mannequin):
    out = {"format": EXTRAS_FORMAT, "version": EXTRAS_VERSION, "name": mannequin.name, "role": mannequin.role,
           "units": "m (geometry), cm (measurements)",
           "up": "ElliMann data is Z-up, facing -Y; glTF nodes are Y-up as glTF requires",
           "measured_cm": mannequin.measure()}
    if mannequin.measurements:
        out["target_cm"] = {k: float(v) for k, v in mannequin.measurements.items()}
    return out


def export_gltf(collection, path):
    """Write a mannequin collection (and its child collections) to a binary glTF (.glb), atomically
    (:func:`atomic.atomic_output`, like every file Blender writes for ElliMann).

    Objects hidden from renders are left out: in a mannequin shown with cushions those are the
    ellipsoids the cushions replace, so the file holds each convex piece once.

    Raises ElliMannError for a path not ending in .glb or for built cushions that are out of date
    (their ellipsoids moved since they were built: a live update, an undo or a reload can leave them
    so), and MannequinError (naming the parts) for a collection that is not a valid mannequin;
    nothing is written then, and the file is unchanged. Returns the path.
    """
    path = os.fspath(path)
    if not path.lower().endswith(".glb"):
        raise ElliMannError(f"path: a glTF export is written as binary glTF and must end in .glb, got {path!r}")
    bpy.context.view_layer.update()  # matrix_world of objects a script just moved
    mannequin = collection_to_mannequin(collection)
    parts = part_lookup(collection)
    stale = [c.name for c in built_objects(collection, "CUSHION") if is_stale(c, parts)]
    if stale:
        more = f" and {len(stale) - 1} more" if len(stale) > 1 else ""
        raise ElliMannError(f"the cushions of '{collection.name}' are out of date ('{stale[0]}'{more}: their "
                            "ellipsoids moved since they were built): Build Cushions first")
    objects = [o for o in objects_recursive(collection) if o.ellimann.is_part]
    saved = []
    try:
        for owner, value in [(o, part_extras(o)) for o in objects] + [(collection, scene_extras(mannequin))]:
            saved.append((owner, owner.get(EXTRAS_KEY)))
            owner[EXTRAS_KEY] = value
        with atomic_output(path) as temp:
            result = bpy.ops.export_scene.gltf(filepath=temp, export_format="GLB", export_extras=True,
                                               collection=collection.name, export_yup=True, use_renderable=True)
            if result != {"FINISHED"}:
                raise ElliMannError(f"path: Blender's glTF exporter did not finish ({result})")
    finally:
        for owner, value in saved:
            if value is None:
                del owner[EXTRAS_KEY]
            else:
                owner[EXTRAS_KEY] = value
    return path


def read_glb_json(path):
    """The JSON chunk of a .glb file as a dict (for tests and tools that check the extras)."""
    with open(path, "rb") as stream:
        header = stream.read(20)
        magic, _, _, length, kind = struct.unpack("<4sIII4s", header)
        if magic != b"glTF" or kind != b"JSON":
            raise ElliMannError(f"path: {path} is not a binary glTF file")
        return json.loads(stream.read(length))

