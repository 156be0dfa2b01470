"""``ellimann drape``: a garment sized from a mannequin, draped with Blender's cloth (Blender), saved as a .blend;
its options and defaults are the Drape panel's (``core.settings.DRAPE``, read into
``core.drape.settings.DrapeSettings``)."""

import argparse
import dataclasses
import os
import sys

from ..core.constants import CM_PER_M
from ..core.files import atomic_output
from ..core.geometry.ellipsoid import bounds
from ..core.pose.kinematics import require_joints
from ..core.pose.motion import clamped_motion
from ..core.pose.standard import POSE_NAMES
from ..core.settings import DRAPE, EDGE_RANGE, LEVELS, garment_help
from . import arguments, output, writing
from .measure import load_blend_mannequin, load_json_mannequin
from .output import PROG, UsageError


def add_parser(commands):
    drape = commands.add_parser(
        "drape",
        help="drape a garment on a mannequin with Blender's cloth simulation",
        description="Build a garment sized from the mannequin's m_T, drape it with "
        "Blender cloth (the mannequin's convex pieces or its skin as the collider), bake the "
        "frames and save the scene as a .blend; prints the fit (garment-to-"
        "body distances, vertices inside the body). Defaults are the Drape "
        "panel's (DrapeSettings).",
    )
    drape.add_argument("mannequin", metavar="MANNEQUIN", help="a .json or .blend mannequin")
    garment = DRAPE["garment"]
    drape.add_argument("--garment", choices=garment.values, default=garment.default, help=garment_help())
    drape.add_argument("--frames", type=int, help=DRAPE["frames"].help.format(default=DRAPE["frames"].default))
    for name in ("collider", "skin_level"):
        option = DRAPE[name]
        drape.add_argument(f"--{name.replace('_', '-')}", choices=option.values, help=option.help)
    drape.add_argument(
        "--cushions",
        action=argparse.BooleanOptionalAction,
        help=DRAPE["cushions"].help.format(default_text="cushions" if DRAPE["cushions"].default else "every ellipsoid"),
    )
    drape.add_argument(
        "--edge",
        type=arguments.number,
        metavar="CM",
        help=DRAPE["edge"].help.format(default_cm=DRAPE["edge"].default * CM_PER_M),
    )
    drape.add_argument(
        "--pose",
        choices=POSE_NAMES,
        metavar="POSE",
        help=f"drape on a moving body: from rest into a standard pose (held), or walking (the cloth "
        f"follows the stride); one of {', '.join(POSE_NAMES)}; needs a mannequin with joints",
    )
    drape.add_argument("--collection", help="the mannequin collection in a .blend holding several (.blend only)")
    drape.add_argument("-o", "--output", required=True, metavar="OUT.blend")
    drape.add_argument("--render", metavar="OUT.png", help="also a Workbench picture of the last frame")
    arguments.add_verbose(drape)
    drape.set_defaults(run=run, blender=needs_blender)


def needs_blender(args):
    """What needs Blender in this command: the cloth simulation."""
    return "the cloth simulation"


def run(args):
    for path, ending, what in ((args.output, ".blend", "-o"), (args.render, ".png", "--render")):
        if path is not None and not path.lower().endswith(ending):
            raise UsageError(f"{what} must end in {ending}, got {path!r}")
    kind = os.path.splitext(args.mannequin)[1].lower()
    if kind not in (".json", ".blend"):
        raise UsageError(f"MANNEQUIN must be a .json or .blend mannequin, got {args.mannequin!r}")
    if kind == ".json" and args.collection is not None:
        raise UsageError(
            f"--collection picks one of the mannequins in a .blend; {args.mannequin} is a .json file "
            "holding one mannequin (leave --collection out)"
        )
    if not os.path.isfile(args.mannequin):
        raise UsageError(f"{args.mannequin}: no such file")
    if kind == ".json":
        mannequin = load_json_mannequin(args.mannequin)
    bpy = writing.blender_module("drape")
    from ..blender.services.chatter import blender_output
    from ..blender.services.drape import WARN_CLOTH_VERTICES, check_cloth_size, drape
    from ..blender.services.scene import add_mannequin, empty_scene

    settings = settings_of(args)
    if kind == ".json":
        motion, loop = motion_of(args, mannequin)
        empty_scene()
        shown = add_mannequin(mannequin, cushions=settings.cushions and bool(mannequin.topology.cushion_pairs))
        if motion or settings.collider == "skin":  # the drape's colliders are the body; the pieces would hide it
            shown.hide_render = shown.hide_viewport = True
    else:
        mannequin = load_blend_mannequin(args.mannequin, args.collection)
        motion, loop = motion_of(args, mannequin)
    vertices, size = check_cloth_size(mannequin, args.garment, settings)  # refuses a cloth too large to drape
    if vertices > WARN_CLOTH_VERTICES:
        output.say(
            f"{PROG} drape: warning: the cloth will have about {vertices:,} vertices and need about "
            f"{size / 1e9:.1f} GB; it is slow (a larger --edge is faster)"
        )
    moving = f" ({args.pose})" if motion else ""
    if settings.collider == "skin":
        collider = f"its skin ({settings.skin_level}, {LEVELS[settings.skin_level]:g} mm voxels)"
    else:
        collider = "cushions" if settings.cushions else "ellipsoids"
    output.say(
        f"{PROG} drape: {args.garment} on '{mannequin.name}'{moving}, {settings.frames} frames, cloth edge "
        f"{settings.edge * CM_PER_M:g} cm, colliding with {collider}"
    )
    progress = output.Progress(
        settings.frames,
        "drape",
        every=max(10, settings.frames // 20),  # 10 frames, 5% past 200
        quiet=args.quiet,
    )

    def frame_done(frame):
        progress.step(
            "frames simulated" + ("; baking and measuring the fit" if frame == settings.frames else ""), frame
        )

    with blender_output():
        try:
            result = drape(mannequin, args.garment, settings, progress=frame_done, motion=motion, loop=loop)
        finally:
            progress.done()
        with writing.writing(args.output), atomic_output(args.output) as temp:
            bpy.ops.wm.save_as_mainfile(filepath=temp, copy=True, check_existing=False)
    output.say(f"wrote {args.output}: {result.garment.name} on '{mannequin.name}', {result.summary()}", file=sys.stdout)
    if args.render:
        from ..blender.services.render import render_view

        body = result.body
        low, high = bounds(body.rotation, body.center, body.semi_axes)
        with writing.writing(args.render):
            render_view(args.render, low.min(axis=0), high.max(axis=0))
        output.say(f"wrote {args.render}", file=sys.stdout)
    return 0


def motion_of(args, mannequin):
    """(core poses or None, whether they loop) of --pose on ``mannequin`` (ElliMannError: no joints)."""
    if args.pose is None or args.pose == "a_pose":
        return None, False
    poses, _, loop = clamped_motion(args.pose, require_joints(mannequin))
    return poses, loop


def settings_of(args):
    """DrapeSettings from the command line: what is not given keeps DrapeSettings' default (the panel's too)."""
    from ..core.drape.settings import DrapeSettings  # the drape's code, loaded only when it runs

    low, high = (bound * CM_PER_M for bound in EDGE_RANGE)
    if args.edge is not None and not low <= args.edge <= high:  # in the flag's unit, not DrapeSettings' metres
        raise UsageError(f"--edge: the cloth's edge length must be from {low:g} to {high:g} cm, got {args.edge:g} cm")
    if args.skin_level is not None and args.collider != "skin":
        raise UsageError("--skin-level sets the skin collider's level: give it with --collider skin")
    given = {
        "frames": args.frames,
        "edge": None if args.edge is None else args.edge / CM_PER_M,
        "cushions": args.cushions,
        "collider": args.collider,
        "skin_level": args.skin_level,
    }
    return dataclasses.replace(DrapeSettings(), **{k: v for k, v in given.items() if v is not None}).checked()
