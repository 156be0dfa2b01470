"""Dev tool (not shipped): the README's draping picture, made as bench/bench_drape.py drapes.

Each garment, built from the Average Reference Mannequin's m_T and moved clear of every body, is
draped (Blender cloth, cushion colliders at the default resolution) on the mannequin and, beside
it, on the dense body it stands for (``../shared/refmodels/average.obj``) or, with ``--versus skin``,
on the mannequin's skin (the drape's skin collider at its default level). Front view, Workbench.

    .venv/bin/python -m tools.pictures.drape_picture [--out docs/images/drape_average.png] [--frames 60]
    .venv/bin/python -m tools.pictures.drape_picture --versus skin --out docs/images/drape_skin.png
"""

import argparse
import os
import tempfile
from dataclasses import replace

import numpy as np

from bench.bench_drape import BODY, EDGE, REFMODELS
from ellimann_addon.core.drape import garments
from ellimann_addon.core.drape.colliders import collision_pieces, skin_collider, skin_distance
from ellimann_addon.core.drape.fit_metrics import BodyPieces, mesh_distance
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry.ellipsoid import bounds
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.synthesis.synthesize import REFERENCE_FOLDER

SPACING = 1.05  # m between slots
BODY_COLOR = (0.8, 0.78, 0.72, 1.0)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="docs/images/drape_average.png")
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--width", type=int, default=2000)
    parser.add_argument("--versus", choices=("dense", "skin"), default="dense", help="beside the mannequin's drape")
    args = parser.parse_args(argv)
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="ellimann-tools-"))
    import bpy

    import ellimann_addon
    from ellimann_addon.blender.bridge.convert import mesh_from_arrays
    from ellimann_addon.blender.services import drape, render
    from ellimann_addon.blender.services.scene import add_mannequin, empty_scene

    ellimann_addon.register()
    mannequin = Mannequin.load(REFERENCE_FOLDER / f"{BODY}.json")
    body = read_obj(REFMODELS / f"{BODY}.obj", up="z")
    body_vertices, body_faces = body.vertices, body.faces
    empty_scene()
    scene = bpy.context.scene
    settings = drape.DrapeSettings(frames=args.frames, edge=EDGE)
    low, high = np.full(3, np.inf), np.full(3, -np.inf)
    exact = BodyPieces(mannequin, cushions=True, subdivisions=4)
    skin = skin_collider(mannequin, settings.skin_level)[0] if args.versus == "skin" else None
    to_skin = skin_distance(skin) if skin is not None else None

    def both_bodies(points):
        if to_skin is not None:
            other = to_skin(points)
        else:
            other = mesh_distance(points, body_vertices, body_faces)[0]
        return np.minimum(exact.signed_distance(points)[0], other)

    slot = 0
    for kind in ("t_shirt", "tube_dress"):
        garment = garments.clear_of(garments.make_garment(mannequin, kind, edge=EDGE), both_bodies)
        for on_body in (False, True):
            offset = np.array([slot * SPACING, 0.0, 0.0])
            moved = replace(garment, vertices=garment.vertices + offset)
            if on_body and args.versus == "skin":
                name = f"skin ({settings.skin_level})"
                obj = bpy.data.objects.new(name, mesh_from_arrays(name, skin.vertices + offset, skin.faces))
                obj.color = BODY_COLOR
                scene.collection.objects.link(obj)
                pieces = [drape.mesh_piece(name, skin.vertices + offset, skin.faces)]
                label = f"{garment.name} on the skin"
            elif on_body:
                obj = bpy.data.objects.new(
                    f"{BODY}.obj", mesh_from_arrays(f"{BODY}.obj", body_vertices + offset, body_faces)
                )
                obj.color = BODY_COLOR
                scene.collection.objects.link(obj)
                pieces = [drape.mesh_piece(f"{BODY}.obj", body_vertices + offset, body_faces)]
                label = f"{garment.name} on {BODY}.obj"
            else:
                copy = mannequin.translated(offset)
                add_mannequin(copy, cushions=True)
                pieces = collision_pieces(copy, True, settings.sphere_subdivisions, settings.cushion_subdivisions)
                label = f"{garment.name} on the mannequin"
            _, cloth, _ = drape.setup(moved, pieces, settings, label)
            drape.bake(scene, cloth, args.frames)
            lo, hi = bounds(mannequin.rotation, mannequin.center, mannequin.semi_axes)
            render._add_label(label, (offset[0], lo[:, 1].min() - 0.2, -0.04), size=0.05)
            low = np.minimum(low, lo.min(axis=0) + offset)
            high = np.maximum(high, hi.max(axis=0) + offset)
            slot += 1
    low[2] -= 0.1  # room for the labels
    print(render.render_view(args.out, low, high, width=args.width))


if __name__ == "__main__":
    main()
