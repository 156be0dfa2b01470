"""Dev tool (not shipped): where each measurement is taken, drawn on a mannequin and on a body (docs/measurements.md).

    python -m tools.pictures.render_measurements [--body NAME] [--mannequin NAME] --out PNG
        [--neck-out PNG [--bodies DIR]]

The body (one of ../shared/refmodels) and the mannequin (a shipped female Reference Mannequin, measured through
its pieces' mesh, the same code as a scan, at its own neck tilt) are drawn semi-transparent, front and side, with
every measurement's loop, the arm's shoulder-to-fingertip line and the crotch point in colour (core.measure.body's
sections). ``--neck-out``: every body of ``--bodies`` (default ../shared/refmodels) from the side, head and
shoulders, with its neck ring square to the neck (purple) and the level ring the neck was before (dark grey).
"""

import argparse
import json
from pathlib import Path

import bpy
import numpy as np

import ellimann_addon
from ellimann_addon.blender.bridge.convert import mannequin_to_collection
from ellimann_addon.blender.services.teardown import exit_with
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry.mesh import hull_girth, icosphere
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.measure.band_search import extreme_over_band
from ellimann_addon.core.measure.body import StandingBody, measure_body_mesh
from ellimann_addon.core.measure.body_neck import NECK_SAMPLES, body_neck
from ellimann_addon.core.measure.extra import mannequin_tilt
from ellimann_addon.core.measure.neck import NECK_BAND
from ellimann_addon.core.synthesis.shipped import reference_folder

from ..shipped.reference_sets import TRACING_FOLDER
from .render import Slot, render

COLORS = {
    "Sh": (0.9, 0.6, 0.1, 1),
    "Br": (0.85, 0.2, 0.2, 1),
    "Wa": (0.2, 0.6, 0.2, 1),
    "Hi": (0.2, 0.35, 0.85, 1),
    "neck": (0.7, 0.2, 0.7, 1),
    "upper_arm": (0.1, 0.7, 0.7, 1),
    "thigh": (0.95, 0.45, 0.6, 1),
    "calf": (0.55, 0.35, 0.15, 1),
    "crotch_height": (0.05, 0.05, 0.05, 1),
    "arm_length": (0.95, 0.85, 0.1, 1),
    "level neck": (0.25, 0.25, 0.25, 1),
}
BUST = 0.74  # He: the neck picture shows each body from here up


def pieces_mesh(mannequin, level=4):
    unit, faces = icosphere(level)
    vertices = [(unit * a) @ r.T + c for r, c, a in zip(mannequin.rotation, mannequin.center, mannequin.semi_axes)]
    return np.concatenate(vertices), np.concatenate([faces + i * len(unit) for i in range(len(vertices))])


def marks(sections, name):
    """Curve objects (and a ball for the crotch) where each measurement is taken."""
    made = []
    for key, points in sections.items():
        if len(points) == 0:
            continue
        if len(points) == 1:
            mesh = bpy.data.meshes.new(f"{name} {key}")
            unit, faces = icosphere(2)
            mesh.from_pydata((unit * 0.012 + points[0]).tolist(), [], faces.tolist())
            obj = bpy.data.objects.new(f"{name} {key}", mesh)
        else:
            curve = bpy.data.curves.new(f"{name} {key}", "CURVE")
            curve.dimensions = "3D"
            curve.bevel_depth = 0.006
            spline = curve.splines.new("POLY")
            spline.points.add(len(points) - 1)
            for point, xyz in zip(spline.points, points):
                point.co = (*xyz, 1.0)
            spline.use_cyclic_u = len(points) > 2
            obj = bpy.data.objects.new(f"{name} {key}", curve)
        obj.color = COLORS[key]
        bpy.context.scene.collection.objects.link(obj)
        made.append(obj)
    bpy.context.view_layer.update()  # a curve's bounding box is the unit box until it is evaluated
    return made


def level_neck(body):
    """(girth m, loop (k, 3)) of the neck as it was before issue 26: the smallest whole level section between
    NECK_BAND He."""

    def girths(heights):
        values = np.array([hull_girth(body.section(z)[0].reshape(-1, 2))[0] for z in heights])
        return np.where(values > 0.0, values, np.inf)

    girth, z = extreme_over_band(girths, *(body.at(f) for f in NECK_BAND), False, samples=NECK_SAMPLES, where=True)
    hull = hull_girth(body.section(z)[0].reshape(-1, 2))[1]
    return girth, np.c_[hull, np.full(len(hull), z)]


def mesh_object(name, vertices, faces):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(np.asarray(vertices).tolist(), [], np.asarray(faces).tolist())
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def neck_picture(folder, out):
    """Every body of ``folder`` from the side, head and shoulders, with its neck ring and the level one before (in
    the order of the folder's skeleton.json)."""
    slots = []
    for path in (folder / f"{name}.obj" for name in json.loads((folder / "skeleton.json").read_text())["bodies"]):
        body = read_obj(path, up="z")
        standing = StandingBody(body.vertices, body.faces)
        girth, tilt, loop = body_neck(standing)
        old, old_loop = level_neck(standing)
        print(f"{path.stem}: neck {100 * girth:.2f} cm at {np.degrees(tilt):.1f} degrees, level {100 * old:.2f} cm")
        above = (body.vertices[body.faces, 2] > standing.at(BUST)).all(axis=1)
        used, faces = np.unique(body.faces[above], return_inverse=True)  # only its vertices: they frame the picture
        bust = mesh_object(path.stem, body.vertices[used], faces.reshape(-1, 3))
        rings = marks({"neck": loop, "level neck": old_loop}, path.stem)
        slots.append(Slot(solid=rings, ghosts=[bust], turn=90))
    render(out, slots, resolution=(2400, 800), spacing=0.12)
    print(f"wrote {out}")


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m tools.pictures.render_measurements", description=__doc__.split("\n")[0]
    )
    parser.add_argument("--body", default="average")
    parser.add_argument("--mannequin", default="average")
    parser.add_argument("--out", required=True)
    parser.add_argument("--neck-out", help="also draw every body's neck ring to this PNG")
    parser.add_argument("--bodies", type=Path, default=TRACING_FOLDER, help="the bodies of --neck-out")
    args = parser.parse_args(argv)
    ellimann_addon.register()
    mannequin = Mannequin.load(reference_folder("female") / f"{args.mannequin}.json")
    collection = mannequin_to_collection(mannequin)
    measured = measure_body_mesh(*pieces_mesh(mannequin), mannequin.section_fractions, mannequin_tilt(mannequin))
    mannequin_marks = marks(measured.sections, "mannequin")
    body = read_obj(TRACING_FOLDER / f"{args.body}.obj", up="z")
    body_object = mesh_object(args.body, body.vertices, body.faces)
    body_marks = marks(measure_body_mesh(body.vertices, body.faces).sections, "body")
    slots = [
        Slot(solid=marks_, ghosts=[ghost], turn=turn)
        for marks_, ghost in ((mannequin_marks, collection), (body_marks, body_object))
        for turn in (0, 90)
    ]
    render(args.out, slots, resolution=(1800, 1100), spacing=0.25)
    print(f"wrote {args.out}")
    if args.neck_out:
        neck_picture(args.bodies, args.neck_out)


if __name__ == "__main__":
    main()
    exit_with(0)
