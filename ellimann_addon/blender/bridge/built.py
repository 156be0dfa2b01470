"""Things ElliMann builds from a mannequin (cushion meshes, section curves, the skin) and may rebuild.

They live in child collections of the mannequin, tagged with the ID property ``ellimann_built``,
and each object is tagged with ``Object.ellimann.kind``. Rebuilding removes only objects that carry
both tags, so anything a user put into those collections stays.
"""

import bpy
import numpy as np

from .convert import SIDE_COLORS, mesh_from_arrays, new_collection

BUILT_KEY = "ellimann_built"
SOURCE_KEY = "ellimann_source"  # on a cushion: its ellipsoids' matrices relative to it, when it was built
STALE_TOLERANCE = 1e-5
CHILD_NAMES = {"CUSHION": "Cushions", "SECTION": "Sections", "SKIN": "Skin"}
SECTION_BEVEL = 0.003  # m: curves need a bevel to show in renders
SECTION_COLOR = (0.1, 0.35, 0.9, 1.0)


def built_collections(mannequin, kind):
    return [c for c in mannequin.children if c.get(BUILT_KEY) == kind]


def built_objects(mannequin, kind):
    """Objects of ``kind`` that ElliMann built for ``mannequin``."""
    found = []
    for collection in built_collections(mannequin, kind):
        found += [o for o in collection.objects if o.ellimann.is_part and o.ellimann.kind == kind]
    return found


def built_owner(collection):
    """The mannequin a built child collection belongs to, or None."""
    if collection is None or not collection.get(BUILT_KEY):
        return None
    for parent in bpy.data.collections:
        if parent.ellimann.is_mannequin and parent.children.get(collection.name) == collection:
            return parent
    return None


def remove_built(mannequin, kind):
    """Delete the objects of ``kind`` built for ``mannequin`` (and their data if nothing else uses it)."""
    removed = 0
    for obj in built_objects(mannequin, kind):
        data = obj.data
        bpy.data.objects.remove(obj)
        removed += 1
        if data is not None and data.users == 0:
            (bpy.data.meshes if isinstance(data, bpy.types.Mesh) else bpy.data.curves).remove(data)
    return removed


def built_collection(mannequin, kind):
    """The mannequin's child collection for ``kind``: the existing one, or a new one."""
    found = built_collections(mannequin, kind)
    if found:
        return found[0]
    collection = new_collection(f"{mannequin.name} {CHILD_NAMES[kind]}", mannequin)
    collection[BUILT_KEY] = kind
    return collection


def tag_built(obj, kind, part_name, side="C", partner="", region="", girth=False):
    props = obj.ellimann
    props.is_part = True
    props.kind = kind
    props.part_name = part_name
    props.side = side
    props.partner = partner
    props.region = region
    props.girth = girth


def _relative(cushion_matrix, first, second):
    """The two ellipsoids' object matrices in the cushion's frame (unchanged when all move rigidly together)."""
    inverse = np.linalg.inv(np.array(cushion_matrix))
    return np.concatenate([(inverse @ np.array(o.matrix_world))[:3].ravel() for o in (first, second)])


def new_cushion_object(name, first, second, local_vertices, faces, frame, collection):
    """A cushion mesh object for the ellipsoid objects ``first`` and ``second``; ``frame`` is the rigid
    frame of the first (vertices are local to it)."""
    mesh = mesh_from_arrays(name, local_vertices, faces)
    obj = bpy.data.objects.new(name, mesh)
    a, b = first.ellimann, second.ellimann
    tag_built(obj, "CUSHION", a.part_name, a.side, b.part_name, a.region, a.girth or b.girth)
    obj.matrix_world = frame
    obj[SOURCE_KEY] = _relative(frame, first, second).tolist()
    obj.color = SIDE_COLORS[a.side]
    collection.objects.link(obj)
    return obj


def is_stale(cushion, parts):
    """True if the cushion's ellipsoids (``parts``: part name -> object) moved or changed since it was built."""
    first, second = parts.get(cushion.ellimann.part_name), parts.get(cushion.ellimann.partner)
    stored = cushion.get(SOURCE_KEY)
    if first is None or second is None or stored is None:
        return True
    current = _relative(cushion.matrix_world, first, second)
    return len(stored) != len(current) or not np.allclose(np.array(stored), current, atol=STALE_TOLERANCE)


def new_section_object(name, key, z, points, collection):
    """A closed poly curve through hull points (k, 2) at height z."""
    curve = bpy.data.curves.new(name, "CURVE")
    curve.dimensions = "3D"
    curve.bevel_depth = SECTION_BEVEL
    spline = curve.splines.new("POLY")
    spline.points.add(len(points) - 1)
    co = np.column_stack([points, np.full(len(points), z), np.ones(len(points))])
    spline.points.foreach_set("co", co.astype(np.float32).ravel())
    spline.use_cyclic_u = True
    obj = bpy.data.objects.new(name, curve)
    tag_built(obj, "SECTION", key)
    obj.color = SECTION_COLOR
    collection.objects.link(obj)
    return obj
