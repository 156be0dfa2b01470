"""Dev tool (not shipped): Workbench pictures of posing, for docs/posing.md.

    python -m tools.pictures.pose_pictures poses OUT.png [--mannequin RM.json]  # the five standard poses side by side
    python -m tools.pictures.pose_pictures walk-drape OUT.png [--frames N]      # a frame of the tube dress on the walk
    python -m tools.pictures.pose_pictures clip OUT.png               # a BVH clip, beside Blender's import of it

Each mannequin is rigged and posed the way the Pose panel does it (``services.rig``; the walk shown at its
frame 7, mid-stride); the walking drape is ``services.drape`` with the walk as its motion, three of its
frames side by side, seen from the side. The clip is devkit.clips' Biovision-named test clip (18 bones, inches,
arms hanging at rest): at four of its frames the mannequin following it (``core.pose.clip``, the Import BVH
operator's path) beside a stick figure of Blender's own import of the clip (``import_anim.bvh``), scaled by the
hip heights as the mannequin's root is.
"""

import argparse
import pathlib
import tempfile

import bpy
import numpy as np

import ellimann_addon
from ellimann_addon.blender.bridge.convert import objects_recursive
from ellimann_addon.blender.services import teardown
from ellimann_addon.blender.services.chatter import blender_output
from ellimann_addon.blender.services.drape import DrapeSettings, drape
from ellimann_addon.blender.services.render import render_view
from ellimann_addon.blender.services.rig import build_rig, pose_standard
from ellimann_addon.blender.services.scene import add_mannequin, empty_scene
from ellimann_addon.core.files import atomic_output
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.pose.motion import clamped_motion
from ellimann_addon.core.pose.standard import POSE_NAMES
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

SPACING = 1.3  # m between mannequins of the line-up
WALK_FRAME = 7


def poses_picture(mannequin, path, width=2000):
    """The standard poses of ``mannequin`` side by side, seen from the front and a little to the side."""
    with blender_output():
        scene = empty_scene()
        for index, name in enumerate(POSE_NAMES):
            placed = mannequin.translated((SPACING * (index - (len(POSE_NAMES) - 1) / 2), 0.0, 0.0))
            placed.name = name
            collection = add_mannequin(placed, cushions=True)
            rig = build_rig(collection, placed)
            pose_standard(rig, placed.joints, name, scene, name)
        scene.frame_set(WALK_FRAME)
        half = SPACING * len(POSE_NAMES) / 2
        render_view(path, np.array([-half, -0.6, 0.0]), np.array([half, 0.6, 1.75]), width=width, azimuth=20.0)
    return path


def walk_drape_picture(mannequin, path, frames=48, shown=(36, 42, 48), width=700):
    """A tube dress draped on the walking mannequin: the frames ``shown`` side by side, seen from its left
    side, each framed on the body where it is then."""
    poses, _, loop = clamped_motion("walk", mannequin.joints)
    with blender_output():
        scene = empty_scene()
        standing = add_mannequin(mannequin, cushions=True)
        for obj in objects_recursive(standing):  # the drape's colliders are the moving body
            obj.hide_render = True
        result = drape(mannequin, "tube_dress", DrapeSettings(frames=frames, edge=0.02), motion=poses, loop=loop)
        rig = next(o for o in result.collection.objects if o.type == "ARMATURE")
        pictures = []
        with tempfile.TemporaryDirectory() as folder:
            for frame in shown:
                scene.frame_set(frame)
                pelvis = np.array(rig.matrix_world @ rig.pose.bones["Pelvis"].head)
                low, high = pelvis + (-0.5, -0.5, -pelvis[2]), pelvis + (0.5, 0.5, 1.75 - pelvis[2])
                pictures.append(render_view(str(pathlib.Path(folder) / f"{frame}.png"), low, high, width, 80.0))
            side_by_side(pictures, path)
    print(f"walk drape: {result.summary()}")
    return path


def clip_picture(mannequin, path, shown=(1, 7, 13, 19), width=2000):
    """The mannequin following the Biovision test clip at frames ``shown``, each beside Blender's import of it."""
    from devkit import bvh, clips
    from devkit.blender_bvh import blender_heads
    from ellimann_addon.blender.services.rig import apply_pose
    from ellimann_addon.core.formats.bvh import read_bvh
    from ellimann_addon.core.pose.clip import clip_onto

    with tempfile.TemporaryDirectory() as folder, blender_output():
        clip_path = bvh.write_bvh(
            pathlib.Path(folder) / "biovision.bvh", clips.convention_clip("biovision", mannequin.joints)
        )
        read = read_bvh(clip_path)
        poses = clip_onto(mannequin, read.motion, read.match).poses
        heads = blender_heads(clip_path) * read.unit
        empty_scene()
        pelvis = read.match.sources[0]
        scale = (mannequin.joints[0, 2]) / (read.motion.rest_heads[pelvis, 2] - read.motion.rest_floor)
        for index, frame in enumerate(shown):
            x = 2 * SPACING * (index - (len(shown) - 1) / 2)
            placed = mannequin.translated((x - 0.4, 0.0, 0.0))
            placed.name = f"frame {frame}"
            rig = build_rig(add_mannequin(placed, cushions=True), placed)
            apply_pose(rig, poses[frame - 1])
            figure = scale * (heads[frame - 1] - heads[0, pelvis] * (1.0, 1.0, 0.0)) + (
                x + 0.5,
                placed.joints[0, 1],
                0.0,
            )
            _stick_figure(f"Blender's import, frame {frame}", figure, read.motion.parents)
        half = SPACING * len(shown)
        render_view(path, np.array([-half, -0.6, 0.0]), np.array([half, 0.6, 1.75]), width=width, azimuth=15.0)
    return path


def _stick_figure(name, heads, parents, thickness=0.02):
    """A mesh of square rods from each bone's head to its parent's (a skeleton Workbench can draw)."""
    vertices, faces = [], []
    for child, parent in enumerate(parents):
        if parent < 0:
            continue
        a, b = heads[parent], heads[child]
        along = (b - a) / max(np.linalg.norm(b - a), 1e-9)
        side = np.cross(along, [0.0, 0.0, 1.0] if abs(along[2]) < 0.9 else [1.0, 0.0, 0.0])
        side = thickness * side / np.linalg.norm(side)
        up = np.cross(along, side)
        base = len(vertices)
        for end in (a, b):
            vertices += [end + side + up, end - side + up, end - side - up, end + side - up]
        faces += [[base + k, base + (k + 1) % 4, base + 4 + (k + 1) % 4, base + 4 + k] for k in range(4)]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in vertices], [], faces)
    obj = bpy.data.objects.new(name, mesh)
    obj.color = (0.85, 0.25, 0.15, 1.0)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def side_by_side(paths, out):
    """One PNG of equally sized PNGs in a row (through Blender's image API), written atomically."""
    images = [bpy.data.images.load(str(p)) for p in paths]
    width, height = images[0].size
    row = np.concatenate([np.array(im.pixels[:], dtype=np.float32).reshape(height, width, 4) for im in images], axis=1)
    combined = bpy.data.images.new("side by side", width * len(images), height, alpha=True)
    combined.pixels.foreach_set(row.ravel())
    with atomic_output(out) as temp:
        combined.filepath_raw, combined.file_format = temp, "PNG"
        combined.save()
    for image in [*images, combined]:
        bpy.data.images.remove(image)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.pictures.pose_pictures", description=__doc__.splitlines()[0])
    parser.add_argument("what", choices=("poses", "walk-drape", "clip"))
    parser.add_argument("out", metavar="OUT.png")
    parser.add_argument("--mannequin", default=str(REFERENCE_FOLDER / "average.json"))
    parser.add_argument("--frames", type=int, default=48)
    args = parser.parse_args(argv)
    ellimann_addon.register()
    mannequin = Mannequin.load(args.mannequin)
    if args.what == "poses":
        poses_picture(mannequin, args.out)
    elif args.what == "clip":
        clip_picture(mannequin, args.out)
    else:
        walk_drape_picture(mannequin, args.out, args.frames)
    print(f"wrote {args.out}")
    bpy.ops.wm.read_homefile(use_empty=True)


if __name__ == "__main__":
    main()
    teardown.exit_with(0)
