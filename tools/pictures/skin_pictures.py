"""Dev tool (not shipped): the skin's pictures for docs/skin.md, Workbench renders of skins made at the final level.

    .venv/bin/python -m tools.pictures.skin_pictures [--only NAME ...] [--voxel MM] [--out DIR]

- ``skin_reference_lineup.png``, ``skin_reference_lineup_male.png``: the five Reference Mannequins of each shipped
  set with their skins, front;
- ``skin_table_2_5.png``: the ten Table 2.5 mannequins (the paper's test requests), synthesized and skinned;
- ``skin_twin_held_out.png``: the neutral reference body (held out of the shipped set of five) beside its skinned
  twin (synthesized from everything it measures, stood in the body), front and side;
- ``skin_poses.png``: the Average RM's skin in every standard pose and three walk frames (front for the arms' poses,
  side for sit and the walk), posed by linear-blend skinning with its bone weights (``core.skin.skinning``);
- ``skin_gap_sections.png``: female-fine Small Chubby's left upper arm and flank cut at five heights, its skin made
  with the gap the skin keeps between pieces that do not touch and without it.
"""

import argparse
from pathlib import Path

import bpy
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402 (after the backend is chosen: no display here)
from matplotlib.collections import LineCollection  # noqa: E402

import ellimann_addon
from ellimann_addon.blender.bridge.convert import mesh_from_arrays
from ellimann_addon.blender.bridge.skin import SKIN_COLOR
from ellimann_addon.core.constants import TABLE_2_5
from ellimann_addon.core.files import atomic_output
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry.mesh import euler_characteristic, section_segments
from ellimann_addon.core.geometry.volume import IOU_MARGIN, BodyVolume
from ellimann_addon.core.mannequin.skin_record import SkinSettings
from ellimann_addon.core.measure.body import measure_body_mesh
from ellimann_addon.core.measure.extra import split_measurements
from ellimann_addon.core.pose.motion import clamped_motion
from ellimann_addon.core.pose.standard import STILL_POSES
from ellimann_addon.core.skin.field import skin_pieces
from ellimann_addon.core.skin.surface import build_skin, outer_mesh
from ellimann_addon.core.synthesis.shipped import named_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize, synthesize_extra
from tools.figures.overlap import standing_in
from tools.pictures.render import Slot, render
from tools.shipped.build_reference import DEFAULT_REFMODELS

IMAGES = Path(__file__).resolve().parents[2] / "docs" / "images"
BODY_COLOR = (0.62, 0.64, 0.7, 1.0)
WALK_FRAMES = (0, 6, 12)
PICTURES = ("lineup", "lineup_male", "table_2_5", "twin", "poses", "gap")
GAP_HEIGHTS = (1.02, 1.035, 1.05, 1.065, 1.08)  # m: where female-fine Small Chubby's upper arm nears its flank


def skin_object(name, vertices, faces, color=SKIN_COLOR):
    mesh = mesh_from_arrays(name, vertices, faces)
    mesh.shade_smooth()
    obj = bpy.data.objects.new(name, mesh)
    obj.color = color
    bpy.context.scene.collection.objects.link(obj)
    return obj


def skin_of(mannequin, settings):
    skin = build_skin(mannequin, settings)
    return skin_object(mannequin.name or "Skin", skin.vertices, skin.faces)


def lineup(set_name, settings, out):
    reference = named_reference_set(set_name)
    slots = [Slot(solid=[skin_of(m, settings)]) for m in reference.mannequins]
    return render(out, slots, resolution=(2400, 1000))


def table_2_5(settings, out):
    reference = named_reference_set("female")
    slots = []
    for request in TABLE_2_5:
        mannequin = synthesize(reference, request)[0]
        slots.append(Slot(solid=[skin_of(mannequin, settings)]))
    return render(out, slots, resolution=(4000, 900))


def twin(settings, out):
    body = read_obj(DEFAULT_REFMODELS / "reference_female.obj", up="z")
    five, extra = split_measurements(measure_body_mesh(body.vertices, body.faces).values)
    grid = BodyVolume(body.vertices, body.faces).grid(0.005, margin=IOU_MARGIN)
    mannequin = standing_in(grid, synthesize_extra(named_reference_set("female"), five, extra)[0])
    body_object = skin_object("Reference body", body.vertices, body.faces, BODY_COLOR)
    skinned = skin_of(mannequin.copy(name="Twin"), settings)
    slots = [Slot(solid=[body_object]), Slot(solid=[skinned]), Slot(solid=[body_object], turn=90.0)]
    slots.append(Slot(solid=[skinned], turn=90.0))
    return render(out, slots, resolution=(2000, 1000))


def poses(settings, out):
    mannequin = named_reference_set("female").mannequins[4]
    skin = build_skin(mannequin, settings)
    shown = [(name, clamped_motion(name, mannequin.joints)[0][0]) for name in STILL_POSES]
    walk = clamped_motion("walk", mannequin.joints)[0]
    shown += [(f"walk {k}", walk[k]) for k in WALK_FRAMES]
    slots = []
    for name, pose in shown:
        pose = pose.copy(translation=pose.translation * [0.0, 0.0, 1.0])  # in place: the slots stay apart
        obj = skin_object(name, skin.posed(pose), skin.faces)
        slots.append(Slot(solid=[obj], turn=0.0 if name in ("a_pose", "t_pose", "attention") else 90.0))
    return render(out, slots, resolution=(3200, 1000))


def without_gap(mannequin, settings):
    """(vertices, faces) of ``mannequin``'s skin made as build_skin makes it, but no pieces kept apart."""
    pieces = skin_pieces(mannequin, settings.blend, settings.voxel).without_gaps()
    return outer_mesh(pieces, settings.voxel, mannequin.topology.names)[:2]


def gap_sections(settings, out):
    mannequin = next(m for m in named_reference_set("female-fine").mannequins if m.name == "Small Chubby")
    skin = build_skin(mannequin, settings)
    meshes = {"without": without_gap(mannequin, settings), "with": (skin.vertices, skin.faces)}
    styles = {"without": ("0.6", 2.5), "with": ("tab:red", 1.0)}
    figure, axes = plt.subplots(1, len(GAP_HEIGHTS), figsize=(4.0 * len(GAP_HEIGHTS), 4.4))
    for ax, height in zip(axes, GAP_HEIGHTS):
        for name, (color, width) in styles.items():
            segments, _ = section_segments(*meshes[name], height)
            ax.add_collection(LineCollection(segments, colors=color, linewidths=width))
        ax.set_xlim(0.15, 0.3)
        ax.set_ylim(-0.12, 0.03)
        ax.set_aspect("equal")
        ax.set_title(f"z = {height:.3f} m")
    for name, (color, width) in styles.items():
        label = f"{name} the gap: Euler characteristic {euler_characteristic(*meshes[name])}"
        axes[0].plot([], [], color=color, lw=width, label=label)
    axes[0].legend(loc="lower left", fontsize=8)
    figure.suptitle(
        f"female-fine Small Chubby's skin at {settings.voxel_mm:g} mm cut through its left upper arm and flank "
        "(seen from above, the front down; x, y in m)"
    )
    figure.tight_layout()
    with atomic_output(out) as temp:
        figure.savefig(temp, dpi=80)
    plt.close(figure)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.pictures.skin_pictures", description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", choices=PICTURES, default=list(PICTURES))
    parser.add_argument("--voxel", type=float, default=None, help="the skin's voxel in mm (default: the final level)")
    parser.add_argument("--out", type=Path, default=IMAGES)
    args = parser.parse_args(argv)
    settings = SkinSettings.at_level("final", args.voxel)
    ellimann_addon.register()
    try:
        jobs = {
            "lineup": lambda: lineup("female", settings, args.out / "skin_reference_lineup.png"),
            "lineup_male": lambda: lineup("male", settings, args.out / "skin_reference_lineup_male.png"),
            "table_2_5": lambda: table_2_5(settings, args.out / "skin_table_2_5.png"),
            "twin": lambda: twin(settings, args.out / "skin_twin_held_out.png"),
            "poses": lambda: poses(settings, args.out / "skin_poses.png"),
            "gap": lambda: gap_sections(settings, args.out / "skin_gap_sections.png"),
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
