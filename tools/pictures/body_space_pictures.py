"""Dev tool (not shipped): the body space's pictures for docs/body_space.md, Workbench renders (tools/render.py).

    .venv/bin/python -m tools.pictures.body_space_pictures [--set female] [--body bank_50] [--out PNG]

A body of the set's body space held out (the space made again from the other 85), beside its body skins from its
five and from its eleven measurements (ridge regression, exact inputs, the correction of the five), each with the
body drawn as a ghost over it; front and side.
"""

import argparse
from pathlib import Path

import bpy
import numpy as np

import ellimann_addon
from ellimann_addon.core.body.ridge import EXACT, RidgeBodyModel
from ellimann_addon.core.body.skin import BodySkinMaker
from ellimann_addon.core.measurements import ALL_MEASUREMENTS, MEASUREMENTS
from ellimann_addon.core.synthesis.bodies import load_set_bodies
from ellimann_addon.core.synthesis.body_space import load_set_body_space, space_from_arrays
from ellimann_addon.core.synthesis.shipped import reference_folder
from tools.pictures.body_skin_pictures import BODY_COLOR, skin_object
from tools.pictures.render import Slot, render
from tools.shipped.add_body_space import training_bodies
from tools.shipped.reference_sets import BUILD_SETS

IMAGES = Path(__file__).resolve().parent.parent / "docs" / "images"


def twins(set_name, body_name):
    """(body vertices, faces, {label: (skin vertices, per-vertex error mm)})."""
    folder = reference_folder(set_name)
    space, bodies = load_set_body_space(folder), load_set_bodies(folder)
    names, vertices, faces, joints = training_bodies(BUILD_SETS[set_name])
    i = names.index(body_name)
    keep = [k for k in range(len(names)) if k != i]
    held = space_from_arrays(
        [names[k] for k in keep], vertices[keep], joints[keep], space.measured[keep], space.fractions
    )
    maker = BodySkinMaker(bodies, RidgeBodyModel(held, EXACT))
    truth = dict(zip(space.keys, space.measured[i]))
    body = vertices[i]
    out = {}
    for label, keys in (("five", MEASUREMENTS), ("eleven", ALL_MEASUREMENTS)):
        skin = maker.make({key: truth[key] for key in MEASUREMENTS}, shape={key: truth[key] for key in keys[5:]})
        twin = skin.vertices + [0.0, 0.0, body[:, 2].min()]
        twin[:, :2] += body[:, :2].mean(axis=0) - twin[:, :2].mean(axis=0)
        out[label] = (twin, float(np.linalg.norm(twin - body, axis=1).mean() * 1e3))
        print(f"{set_name} {body_name} from {label}: {out[label][1]:.1f} mm mean per-vertex error")
    return body, faces, out


def picture(set_name, body_name, out):
    body, faces, made = twins(set_name, body_name)
    body_object = skin_object(body_name, body, faces, BODY_COLOR)
    ghost = skin_object(f"{body_name} ghost", body, faces, BODY_COLOR)
    objects = {label: skin_object(f"from {label}", twin, faces) for label, (twin, _) in made.items()}
    slots = []
    for turn in (0.0, 90.0):
        slots.append(Slot(solid=[body_object], turn=turn))
        slots += [Slot(solid=[objects[label]], ghosts=[ghost], turn=turn) for label in ("five", "eleven")]
    return render(out, slots, resolution=(3000, 1000))


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m tools.pictures.body_space_pictures", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--set", default="female", choices=("female", "male"))
    parser.add_argument("--body", default="bank_50")
    parser.add_argument("--out", type=Path)
    args = parser.parse_args(argv)
    out = args.out or IMAGES / f"body_space_twins_{args.set}.png"
    ellimann_addon.register()
    try:
        bpy.ops.wm.read_homefile(use_empty=True)
        print(f"wrote {picture(args.set, args.body, out)}")
    finally:
        ellimann_addon.unregister()
    return 0


if __name__ == "__main__":
    from ellimann_addon.blender.services import teardown

    teardown.exit_with(main())
