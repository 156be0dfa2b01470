"""Dev tool (not shipped): the FBX avatars of a measurement file, re-imported by Blender's FBX importer and drawn
side by side (Workbench): the A-pose avatar (decimated to the garment tools' budget) front and side, and the
T-pose one with Mixamo's names and its collision proxy beside it.

    python -m tools.pictures.fbx_picture tests/data/sizing/jane.vit --out docs/images/fbx_avatar.png
"""

import argparse
import math
import pathlib
import tempfile

import bpy
import numpy as np

import ellimann_addon
from ellimann_addon.blender.bridge.convert import world_triangles
from ellimann_addon.blender.services.fbx import PROXY_NAME, SKIN_NAME, write_fbx
from ellimann_addon.blender.services.render import render_view
from ellimann_addon.blender.services.scene import empty_scene
from ellimann_addon.core.mannequin.skin_record import SkinSettings
from ellimann_addon.core.sizing.readers import read_measurement_file
from ellimann_addon.core.skin.exact import exact_skin
from ellimann_addon.core.synthesis.shipped import named_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize_extra

SKIN_COLOR = (0.82, 0.72, 0.64, 1.0)
PROXY_COLOR = (0.45, 0.6, 0.85, 1.0)


def _import(path, shift, turn=0.0):
    before = set(bpy.data.objects)
    bpy.ops.import_scene.fbx(filepath=str(path))
    new = [o for o in bpy.data.objects if o not in before]
    for obj in new:
        if obj.parent is None:
            obj.rotation_euler[2] += math.radians(turn)
            obj.location.x += shift
        if obj.type == "MESH":
            obj.color = PROXY_COLOR if obj.name.startswith(PROXY_NAME) else SKIN_COLOR
        if obj.type == "ARMATURE":
            obj.hide_render = True
    return new


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("file", help="a measurement file (.vit, .vst, .json, .csv): its first row")
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    ellimann_addon.register()
    row = read_measurement_file(args.file).rows[0]
    made = synthesize_extra(named_reference_set("female"), row.request(), row.extra())
    exact = exact_skin(made.mannequin, SkinSettings(), row.request(), row.extra())
    request = {**row.request(), **row.extra()}
    folder = pathlib.Path(tempfile.mkdtemp(prefix="fbx-picture-"))
    a = write_fbx(folder / "a.fbx", exact.mannequin, exact.skin, request=request)
    t = write_fbx(
        folder / "t.fbx", exact.mannequin, exact.skin, request=request, pose="t_pose", naming="mixamo", pieces=True
    )
    for out in (a, t):
        worst = max(abs(out.measured[k] - v) for k, v in request.items())
        print(
            f"{out.path}: {out.triangles:,} triangles (from {out.decimated or out.triangles:,}), "
            f"worst miss {worst * 10:.2f} mm"
        )
    empty_scene()
    _import(folder / "a.fbx", -1.3)
    _import(folder / "a.fbx", -0.6, turn=90.0)
    new = _import(folder / "t.fbx", 0.6)
    proxy = [o for o in new if o.name.startswith(PROXY_NAME)]
    for obj in proxy:
        obj.location.x += 1.7
    objects = [o for o in bpy.data.objects if o.type == "MESH"]
    bpy.context.view_layer.update()
    points = np.concatenate([world_triangles(o)[0] for o in objects])
    render_view(args.out, points.min(axis=0), points.max(axis=0), width=2000)
    print(args.out, SKIN_NAME)


if __name__ == "__main__":
    main()
