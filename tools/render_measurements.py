"""Dev tool (not shipped): where each measurement is taken, drawn on a mannequin and on a body (docs/measurements.md).

    python -m tools.render_measurements [--body NAME] [--mannequin NAME] --out PNG

The body (one of ../shared/refmodels) and the mannequin (a shipped female Reference Mannequin, measured through
its pieces' mesh, the same code as a scan) are drawn semi-transparent, front and side, with every measurement's
loop, the arm's shoulder-to-fingertip line and the crotch point in colour (core.measure.body's sections).
"""

import argparse

import bpy
import numpy as np

import ellimann_addon
from ellimann_addon.blender.bridge.convert import mannequin_to_collection
from ellimann_addon.blender.services.teardown import exit_with
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry.mesh import icosphere
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.measure.body import measure_body_mesh
from ellimann_addon.core.synthesis.shipped import reference_folder

from .reference_sets import TRACING_FOLDER
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
}


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


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.render_measurements", description=__doc__.split("\n")[0])
    parser.add_argument("--body", default="average")
    parser.add_argument("--mannequin", default="average")
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    ellimann_addon.register()
    mannequin = Mannequin.load(reference_folder("female") / f"{args.mannequin}.json")
    collection = mannequin_to_collection(mannequin)
    mannequin_marks = marks(
        measure_body_mesh(*pieces_mesh(mannequin), mannequin.section_fractions).sections, "mannequin"
    )
    body = read_obj(TRACING_FOLDER / f"{args.body}.obj", up="z")
    mesh = bpy.data.meshes.new(args.body)
    mesh.from_pydata(body.vertices.tolist(), [], body.faces.tolist())
    body_object = bpy.data.objects.new(args.body, mesh)
    bpy.context.scene.collection.objects.link(body_object)
    body_marks = marks(measure_body_mesh(body.vertices, body.faces).sections, "body")
    slots = [
        Slot(solid=marks_, ghosts=[ghost], turn=turn)
        for marks_, ghost in ((mannequin_marks, collection), (body_marks, body_object))
        for turn in (0, 90)
    ]
    render(args.out, slots, resolution=(1800, 1100), spacing=0.25)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
    exit_with(0)
