"""Parser pieces the subcommands share (synthesis options from ``core.synthesis.options``, mesh axes, reference
sets, poses) and what they turn into for a job (``core.job.request``): the options, the reference set, the pose
asked."""

import argparse

from ..core.errors import ReferenceSetError
from ..core.synthesis.options import SYNTHESIS, SynthesisOptions
from .output import PROG, UsageError, say


def number(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    return value


def add_verbose(parser):
    parser.add_argument(
        "-v",
        "--verbose",
        action="store_true",
        help="also show what Blender prints (on stderr); without it only ElliMann's lines show",
    )
    parser.add_argument(
        "-q", "--quiet", action="store_true", help="no progress line (errors, warnings and the result still show)"
    )


def add_synthesis_options(parser):
    """--mode, --metric, --power, --normalize from ``core.synthesis.options.SYNTHESIS``; --cushions, --references."""
    add_verbose(parser)
    for name, option in SYNTHESIS.items():
        if option.choices:
            parser.add_argument(
                f"--{name}",
                choices=option.values,
                default=option.default,
                help=option.help.format(default=option.default),
            )
        else:
            parser.add_argument(
                f"--{name}", type=number, default=option.default, help=option.help.format(default=option.default)
            )
    parser.add_argument(
        "--cushions",
        action="store_true",
        help="cushions (convex hulls of the cushion pairs) instead of their ellipsoids: shown in "
        ".blend/.glb/.obj outputs, convex mesh geoms in MJCF",
    )
    add_references(parser, "the reference set to synthesize from")


def add_mesh_axes(parser, what, default_up=None):
    """--up and --unit of a command that reads body meshes (``what``: which), as ``core.fitting.body_mesh`` reads
    them; ``default_up`` None: Y for .obj (Blender's OBJ axes), Z for .ply and .stl."""
    from ..core.measure.body import UNITS, UP_AXES

    default = f"{default_up}" if default_up else "y for .obj, as Blender writes it; z for .ply and .stl"
    parser.add_argument(
        "--up", choices=UP_AXES, default=default_up, help=f"{what}: the file's up axis (default: {default})"
    )
    parser.add_argument("--unit", choices=tuple(UNITS), default="m", help=f"{what}: the file's length unit (default m)")


def add_references(parser, what, shipped="female (the default), male, female-fine or male-fine"):
    parser.add_argument(
        "--references",
        metavar="NAME_OR_DIR",
        help=f"{what}: a shipped set, {shipped}, or a folder of Reference Mannequin .json files "
        "(with its reference_set.json manifest)",
    )


def add_pose_option(parser):
    """--pose NAME (a standard pose, a pose .json or a BVH clip), --fps, and a clip's --rig and --keep-on-floor."""
    from ..core.pose.bone_match import AUTO, RIG_CHOICES
    from ..core.pose.standard import POSE_NAMES, WALK_FPS

    parser.add_argument(
        "--pose",
        metavar="NAME",
        help=f"write the mannequin posed: {', '.join(POSE_NAMES)} (walk: an animation, in .json and .xml as its "
        "frames), a pose .json file, or a BVH clip (.bvh: its motion retargeted, clamped to the joints' ranges); "
        "measurements stay the rest pose's",
    )
    parser.add_argument(
        "--fps",
        type=number,
        help=f"frames per second: of walk (default {WALK_FPS}), or a clip resampled to it (default: its own)",
    )
    parser.add_argument(
        "--rig",
        choices=RIG_CHOICES,
        default=AUTO,
        help="whose bone names a .bvh clip uses (default auto: the listed rig that places most joints, or the "
        "bones' own names and hierarchy)",
    )
    parser.add_argument(
        "--keep-on-floor",
        action="store_true",
        help="a .bvh clip: hold the lowest foot on the floor in every frame (the root lifted or lowered)",
    )


def pose_ask(args):
    """The ``core.job.request.PoseAsk`` of --pose, --fps, --rig and --keep-on-floor (None without --pose)."""
    from ..core.job.request import PoseAsk

    if args.pose is None:
        return None
    return PoseAsk(args.pose, args.fps, args.rig, args.keep_on_floor, "; --keep-on-floor holds it on the floor")


def say_clip(args, pose):
    """What a clip's bones became and which will not bend, said once per command (a batch: not per row)."""
    if pose is None or pose.clip is None:
        return
    for line in pose.clip.lines():
        say(f"{PROG} {args.command}: {line}")
    if pose.clip.match.stiff_line():
        say(f"{PROG} {args.command}: warning: {pose.clip.match.stiff_line()}")


def synthesis_options(args, name=None):
    """The SynthesisOptions of the command line (built once per command), named ``name`` (default: from the
    request)."""
    return SynthesisOptions(mode=args.mode, metric=args.metric, power=args.power, normalize=args.normalize, name=name)


def references(args, name_or_dir=None):
    """The reference set of ``name_or_dir`` (default: --references; a shipped set's name or a folder)."""
    from ..core.synthesis.reference_set import load_reference_set
    from ..core.synthesis.shipped import reference_folder

    chosen = name_or_dir or args.references
    try:
        return load_reference_set(reference_folder(chosen))
    except ReferenceSetError as error:
        if chosen:
            raise
        raise UsageError(
            f"{error} (the shipped Reference Mannequins; use --references NAME_OR_DIR for others)"
        ) from None
