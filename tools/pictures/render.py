"""Dev tool (not shipped): headless Workbench renders of mannequins and reference meshes to PNG.

Everything is drawn in a temporary scene from linked copies of the objects (sharing their data),
so the file being rendered is left as it was. Each *slot* is one group of solid things (mannequin
collections or objects) with optional semi-transparent *ghosts* (e.g. the reference body it was
traced over); several slots stand side by side along X for a line-up.

    python -m tools.pictures.render mannequins A.json [B.json ...] [--ghost A.obj ...] --out PNG [--view SIDE]
        [--ghost-shift X Y Z] [--side-too]
    python -m tools.pictures.render poses A.json --out PNG [--view THREE_QUARTER] [--pose NAME ...] [--walk-frame K]
    python -m tools.pictures.render objs A.obj [B.obj ...] --out PNG [--side K ...]
"""

import argparse
import math
from dataclasses import dataclass, field
from pathlib import Path

import bpy
import numpy as np
from mathutils import Matrix

import ellimann_addon
from ellimann_addon.blender.bridge.convert import SIDE_COLORS, mannequin_to_collection, mesh_from_arrays
from ellimann_addon.blender.services.render import workbench, write_png
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.pose.posed_pieces import PosingRig
from ellimann_addon.core.pose.standard import POSE_NAMES, standard_motion

GHOST_COLOR = (0.55, 0.55, 0.58, 0.22)
VIEWS = {"FRONT": 0.0, "SIDE": 90.0, "THREE_QUARTER": 35.0}  # camera turn about Z, degrees


@dataclass
class Slot:
    """One place in the picture: solid collections/objects, and ghosts drawn semi-transparent, turned
    ``turn`` degrees about the vertical (e.g. 90 for a side view next to a front view)."""

    solid: list
    ghosts: list = field(default_factory=list)
    turn: float = 0.0


def _objects(item):
    objects = item.all_objects if isinstance(item, bpy.types.Collection) else [item]
    return [o for o in objects if o.type in ("MESH", "CURVE")]


def _copy(obj, collection, placement, color=None):
    copy = obj.copy()  # a linked copy: shares obj.data
    copy.parent = None
    copy.matrix_world = placement @ obj.matrix_world
    if color is not None:
        copy.color = color
    collection.objects.link(copy)
    return copy


def _bounds(objects):
    points = np.concatenate(
        [
            np.array(obj.bound_box) @ np.array(obj.matrix_world)[:3, :3].T + np.array(obj.matrix_world)[:3, 3]
            for obj in objects
        ]
    )
    return points.min(axis=0), points.max(axis=0)


def render(path, slots, resolution=(800, 1000), view="FRONT", spacing=None, margin=1.08, aa_samples="8"):
    """Render ``slots`` (a Slot or a list of them, side by side) with Workbench to ``path`` (PNG).

    ``spacing`` is the gap between slots in metres (default 15% of the widest); returns the path.
    """
    slots = [slots] if isinstance(slots, Slot) else list(slots)
    scene = bpy.data.scenes.new("ElliMann render")
    made_objects, made_data = [], []
    try:
        # Copy each slot centred on the origin and turned, then move the slots side by side along X.
        placed = []
        for slot in slots:
            lo, hi = _bounds([o for item in slot.solid + slot.ghosts for o in _objects(item)])
            centre = Matrix.Translation((-(lo[0] + hi[0]) / 2.0, -(lo[1] + hi[1]) / 2.0, 0.0))
            placement = Matrix.Rotation(math.radians(slot.turn), 4, "Z") @ centre
            copies = [_copy(o, scene.collection, placement) for item in slot.solid for o in _objects(item)]
            copies += [
                _copy(o, scene.collection, placement, GHOST_COLOR) for item in slot.ghosts for o in _objects(item)
            ]
            placed.append(copies)
            made_objects += copies
        widths = [np.ptp(np.array(_bounds(copies))[:, 0]) for copies in placed]
        gap = spacing if spacing is not None else 0.15 * max(widths)
        x = 0.0
        for copies, width in zip(placed, widths):
            shift = Matrix.Translation((x + width / 2.0, 0.0, 0.0))
            for copy in copies:
                copy.matrix_world = shift @ copy.matrix_world
            x += width + gap
        lo, hi = _bounds(made_objects)
        center = (lo + hi) / 2.0

        turn = math.radians(VIEWS[view])
        right = np.array([math.cos(turn), math.sin(turn), 0.0])
        corners = np.array([[a, b, c] for a in (lo[0], hi[0]) for b in (lo[1], hi[1]) for c in (lo[2], hi[2])])
        width = np.ptp((corners - center) @ right)
        height = hi[2] - lo[2]
        camera_data = bpy.data.cameras.new("ElliMann render camera")
        camera_data.type = "ORTHO"
        camera_data.ortho_scale = (
            margin * max(height, width * resolution[1] / resolution[0]) * (max(resolution) / resolution[1])
        )
        camera_data.clip_end = 100.0
        camera = bpy.data.objects.new("ElliMann render camera", camera_data)
        made_data.append(camera_data)
        made_objects.append(camera)
        scene.collection.objects.link(camera)
        # The camera looks along +Y (at the body's front) for FRONT, turned about Z for the other views.
        back = np.array([math.sin(turn), -math.cos(turn), 0.0])
        camera.location = center + 10.0 * back
        camera.rotation_euler = (math.pi / 2.0, 0.0, turn)
        scene.camera = camera

        made_data.append(workbench(scene))  # the add-on's picture settings (blender.services.render)
        scene.display.render_aa = aa_samples
        scene.render.resolution_x, scene.render.resolution_y = resolution
        scene.render.resolution_percentage = 100
        scene.render.image_settings.color_mode = "RGB"
        scene.render.image_settings.compression = 100
        write_png(scene, path)  # atomic, folders made as needed
    finally:
        for obj in made_objects:
            bpy.data.objects.remove(obj)
        for data in made_data:
            (bpy.data.cameras if isinstance(data, bpy.types.Camera) else bpy.data.worlds).remove(data)
        bpy.data.scenes.remove(scene)
    return path


def import_obj(path):
    """Import an OBJ that is already in Blender's axes (Z up, body facing -Y); returns the new objects."""
    before = set(bpy.data.objects)
    bpy.ops.wm.obj_import(filepath=str(path), forward_axis="Y", up_axis="Z")
    return [o for o in bpy.data.objects if o not in before]


def mannequins(files, ghosts, out, view="FRONT", ghost_shift=(0.0, 0.0, 0.0), side_too=False):
    """Mannequin JSON files side by side, each over its ghost mesh (OBJ) if given, moved by
    ``ghost_shift`` (m: e.g. the registration that moved the mannequin off its body); with
    ``side_too`` each also turned 90 degrees beside it (a front and a side view in one picture)."""
    bpy.ops.wm.read_homefile(use_empty=True)
    if ghosts and len(ghosts) != len(files):
        raise SystemExit(f"give one --ghost per mannequin ({len(files)}), or none")
    slots = []
    for i, path in enumerate(files):
        collection = mannequin_to_collection(Mannequin.load(path))
        body = import_obj(ghosts[i]) if ghosts else []
        for obj in body:
            obj.matrix_world = Matrix.Translation(ghost_shift) @ obj.matrix_world
        slots.append(Slot(solid=[collection], ghosts=body))
        if side_too:
            slots.append(Slot(solid=[collection], ghosts=body, turn=90.0))
    return render(out, slots, resolution=(max(800, 420 * len(slots)), 1000), view=view)


def posed_objects(rig, pose):
    """The mannequin of ``rig`` in ``pose`` as objects in a new collection: the ellipsoids no cushion replaces
    and the posed cushion meshes (those across a joint in their two halves)."""
    body = rig.pose(pose)
    collection = mannequin_to_collection(body.mannequin, name=pose.name)
    topology = body.mannequin.topology
    keep = {topology.names[i] for i in topology.single_parts(cushions=True)}
    objects = [o for o in collection.objects if o.ellimann.part_name in keep]
    for mesh in body.cushions:
        obj = bpy.data.objects.new(mesh.name, mesh_from_arrays(mesh.name, mesh.vertices, mesh.faces))
        obj.color = SIDE_COLORS[topology.parts[int(np.flatnonzero(rig.bones == mesh.bone)[0])].side]
        collection.objects.link(obj)
        objects.append(obj)
    return objects


def poses(path, out, names=POSE_NAMES, view="FRONT", walk_frame=6):
    """One mannequin (a JSON with joints) in each pose of ``names`` side by side, cushions split at the joints
    (``core.pose.posed_pieces``); the walk cycle shown at frame ``walk_frame``."""
    bpy.ops.wm.read_homefile(use_empty=True)
    mannequin = Mannequin.load(path)
    rig = PosingRig(mannequin)
    slots = []
    for name in names:
        frames = standard_motion(name, mannequin.joints)
        pose = frames[walk_frame % len(frames)]
        pose = pose.copy(translation=pose.translation * [1.0, 0.0, 1.0])  # walk in place: the slots stay apart
        slots.append(Slot(solid=posed_objects(rig, pose)))
    return render(out, slots, resolution=(max(800, 420 * len(slots)), 1000), view=view, spacing=0.25)


def objs(files, out, sides=(), color=(0.87, 0.72, 0.62, 1.0)):
    """OBJ files ElliMann wrote (a skin's, ``--skin``) side by side, read by Blender's own OBJ importer in its
    default axes (Y up, -Z forward: the convention every ElliMann OBJ follows), shaded as the file says; the files
    at the 0-based indices ``sides`` also seen from the side."""
    bpy.ops.wm.read_homefile(use_empty=True)
    slots = []
    for path in files:
        before = set(bpy.data.objects)
        bpy.ops.wm.obj_import(filepath=str(path))
        imported = [o for o in bpy.data.objects if o not in before]
        for obj in imported:
            obj.color = color
        slots.append(Slot(solid=imported))
    slots += [Slot(solid=slots[k].solid, turn=90.0) for k in sides]
    return render(out, slots, resolution=(max(800, 300 * len(slots)), 750), spacing=0.25)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.pictures.render", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    lineup = sub.add_parser("mannequins", help="mannequin JSON files side by side")
    lineup.add_argument("files", nargs="+", type=Path)
    lineup.add_argument("--ghost", action="append", default=[], type=Path)
    lineup.add_argument(
        "--ghost-shift",
        nargs=3,
        type=float,
        default=(0.0, 0.0, 0.0),
        metavar=("X", "Y", "Z"),
        help="move the ghost meshes by this much (m), e.g. by the mannequin's registration",
    )
    lineup.add_argument("--side-too", action="store_true", help="each mannequin also seen from the side")
    lineup.add_argument("--out", required=True, type=Path)
    lineup.add_argument("--view", default="FRONT", choices=sorted(VIEWS))
    posing = sub.add_parser("poses", help="one mannequin in the standard poses side by side")
    posing.add_argument("file", type=Path)
    posing.add_argument("--out", required=True, type=Path)
    posing.add_argument("--view", default="FRONT", choices=sorted(VIEWS))
    posing.add_argument("--pose", action="append", choices=POSE_NAMES, help="which poses (default: all five)")
    posing.add_argument("--walk-frame", type=int, default=6, help="the frame of the walk cycle shown (default 6)")
    meshes = sub.add_parser("objs", help="OBJ files ElliMann wrote (Y up), side by side")
    meshes.add_argument("files", nargs="+", type=Path)
    meshes.add_argument("--out", required=True, type=Path)
    meshes.add_argument(
        "--side", action="append", type=int, default=[], help="also the K-th file (0-based) from the side"
    )
    args = parser.parse_args(argv)
    ellimann_addon.register()  # the mannequin collections need ElliMann's properties
    try:
        if args.command == "poses":
            poses(args.file, args.out, args.pose or POSE_NAMES, args.view, args.walk_frame)
        elif args.command == "objs":
            objs(args.files, args.out, args.side)
        else:
            mannequins(args.files, args.ghost, args.out, args.view, args.ghost_shift, args.side_too)
    finally:
        ellimann_addon.unregister()
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    from ellimann_addon.blender.services import teardown

    teardown.exit_with(main())
