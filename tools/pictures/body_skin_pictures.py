"""Dev tool (not shipped): the body skin's pictures for docs/body_skin.md, Workbench renders (tools/pictures/render.py).

    .venv/bin/python -m tools.pictures.body_skin_pictures [--only NAME ...] [--out DIR]

- ``body_skin_lineup.png``, ``body_skin_lineup_male.png``: the body skin at each RM's targets, both shipped sets;
- ``body_skin_table_2_5.png``: the ten Table 2.5 requests (the paper's test requests), female set;
- ``body_skin_twin_held_out.png``: the neutral reference body (not one of the shipped set's five) beside its body
  skin from the five measurements it measures, front and side;
- ``body_skin_poses.png``: the Average's body skin in every still pose and three walk frames;
- ``body_skin_sit.png``: sitting, from the side, the female Average and Small Chubby and the male Average, each
  with the body model's own weights and then with the hips' planes of core.body.hips;
- ``body_skin_reach.png``: grid requests the correction reaches now (narrow shoulders with the arms raised, wide
  shoulders over a slim trunk, the trunk's steepest allowed tapers), front and side.
"""

import argparse
from pathlib import Path

import bpy

import ellimann_addon
from ellimann_addon.blender.bridge.convert import mesh_from_arrays
from ellimann_addon.blender.bridge.skin import SKIN_COLOR
from ellimann_addon.core.body.correct import BodySkinError
from ellimann_addon.core.body.skin import BodySkinMaker
from ellimann_addon.core.constants import TABLE_2_5
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.pose.motion import clamped_motion
from ellimann_addon.core.pose.standard import STILL_POSES
from ellimann_addon.core.synthesis.bodies import load_set_bodies
from ellimann_addon.core.synthesis.shipped import named_reference_set, reference_folder
from tools.pictures.render import Slot, render
from tools.shipped.build_reference import DEFAULT_REFMODELS

IMAGES = Path(__file__).resolve().parents[2] / "docs" / "images"
BODY_COLOR = (0.62, 0.64, 0.7, 1.0)
WALK_FRAMES = (0, 6, 12)
PICTURES = ("lineup", "lineup_male", "table_2_5", "twin", "poses", "sit", "reach")
# (label, levels of He, Sh, Br, Wa, Hi in the female set's ranges: 0 low, 1 middle, 2 high)
REACH = (
    ("Sh 30, arms raised", (1, 0, 1, 1, 1)),
    ("Sh 53 over a slim trunk", (1, 2, 0, 0, 1)),
    ("Br 153 over Wa 102.5", (1, 1, 2, 1, 2)),
    ("Wa 142 over Br 118.5", (1, 1, 1, 2, 1)),
)


def maker(set_name):
    reference = named_reference_set(set_name)
    return reference, BodySkinMaker(load_set_bodies(reference_folder(set_name)), ranges=reference.ranges)


def skin_object(name, vertices, faces, color=SKIN_COLOR):
    mesh = mesh_from_arrays(name, vertices, faces)
    mesh.shade_smooth()
    obj = bpy.data.objects.new(name, mesh)
    obj.color = color
    bpy.context.scene.collection.objects.link(obj)
    return obj


def lineup(set_name, out):
    reference, made = maker(set_name)
    slots = []
    for stem in reference.names:
        skin = made.make(reference.manifest.targets_cm[stem])
        slots.append(Slot(solid=[skin_object(stem, skin.vertices, skin.faces)]))
    return render(out, slots, resolution=(2400, 1000))


def table_2_5(out):
    _, made = maker("female")
    slots = []
    for k, request in enumerate(TABLE_2_5):
        try:
            skin = made.make(dict(zip(MEASUREMENTS, request)) if not isinstance(request, dict) else request)
        except BodySkinError as error:
            print(f"Table 2.5 #{k + 1}: {error}")
            continue
        slots.append(Slot(solid=[skin_object(f"T{k + 1}", skin.vertices, skin.faces)]))
    return render(out, slots, resolution=(4000, 900))


def twin(out):
    _, made = maker("female")
    body = read_obj(DEFAULT_REFMODELS / "reference_female.obj", up="z")
    request = made.tape.measure(body.vertices, MEASUREMENTS)
    skin = made.make(request)
    shift = [0.0, 0.0, body.vertices[:, 2].min()]
    body_object = skin_object("Reference body", body.vertices, body.faces, BODY_COLOR)
    skinned = skin_object("Body skin", skin.vertices + shift, skin.faces)
    slots = [Slot(solid=[body_object]), Slot(solid=[skinned]), Slot(solid=[body_object], turn=90.0)]
    slots.append(Slot(solid=[skinned], turn=90.0))
    return render(out, slots, resolution=(2000, 1000))


def poses(out):
    reference, made = maker("female")
    skin = made.make(reference.manifest.targets_cm["average"])
    shown = [(name, clamped_motion(name, skin.joints)[0][0]) for name in STILL_POSES]
    walk = clamped_motion("walk", skin.joints)[0]
    shown += [(f"walk {k}", walk[k]) for k in WALK_FRAMES]
    slots = []
    for name, pose in shown:
        pose = pose.copy(translation=pose.translation * [0.0, 0.0, 1.0])  # in place: the slots stay apart
        obj = skin_object(name, skin.posed(pose), skin.faces)
        slots.append(Slot(solid=[obj], turn=0.0 if name in ("a_pose", "t_pose", "attention") else 90.0))
    return render(out, slots, resolution=(3200, 1000))


def sit(out):
    from ellimann_addon.core.body.hips import largest, skinned
    from ellimann_addon.core.geometry.mesh import volume

    slots = []
    for set_name, stem in (("female", "average"), ("female", "small_chubby"), ("male", "average")):
        reference, made = maker(set_name)
        skin = made.make(reference.manifest.targets_cm[stem])
        pose = clamped_motion("sit", skin.joints)[0][0]
        own = skinned(skin.vertices, skin.joints, *largest(made.bodies.dense_weights), pose)
        for label, vertices in (("own weights", own), ("hips' planes", skin.posed(pose))):
            change = volume(vertices, skin.faces) / skin.volume - 1.0
            print(f"sit {set_name} {stem} {label}: volume {change:+.1%}")
            obj = skin_object(f"{set_name} {stem} {label}", vertices, skin.faces)
            slots.append(Slot(solid=[obj], turn=90.0))
    return render(out, slots, resolution=(3000, 900))


def reach(out):
    reference, made = maker("female")
    ranges = reference.ranges
    slots = []
    for label, levels in REACH:
        request = {k: ranges[k][0] + 0.5 * i * (ranges[k][1] - ranges[k][0]) for k, i in zip(MEASUREMENTS, levels)}
        skin = made.make(request)
        print(f"{label}: {', '.join(f'{k} {v:.1f}' for k, v in request.items())}; arms raised {skin.abduction:.2f} rad")
        obj = skin_object(label, skin.vertices, skin.faces)
        slots += [Slot(solid=[obj]), Slot(solid=[obj], turn=90.0)]
    return render(out, slots, resolution=(3600, 1000))


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m tools.pictures.body_skin_pictures", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--only", nargs="+", choices=PICTURES, default=list(PICTURES))
    parser.add_argument("--out", type=Path, default=IMAGES)
    args = parser.parse_args(argv)
    ellimann_addon.register()
    try:
        jobs = {
            "lineup": lambda: lineup("female", args.out / "body_skin_lineup.png"),
            "lineup_male": lambda: lineup("male", args.out / "body_skin_lineup_male.png"),
            "table_2_5": lambda: table_2_5(args.out / "body_skin_table_2_5.png"),
            "twin": lambda: twin(args.out / "body_skin_twin_held_out.png"),
            "poses": lambda: poses(args.out / "body_skin_poses.png"),
            "sit": lambda: sit(args.out / "body_skin_sit.png"),
            "reach": lambda: reach(args.out / "body_skin_reach.png"),
        }
        for name in args.only:
            bpy.ops.wm.read_homefile(use_empty=True)
            print(f"wrote {jobs[name]()}")
    finally:
        ellimann_addon.unregister()
    return 0


if __name__ == "__main__":
    from ellimann_addon.blender.services import teardown

    teardown.exit_with(main())
