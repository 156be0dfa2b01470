"""Parser pieces the subcommands share (synthesis options from ``core.synthesis.options``, mesh axes, reference
sets, poses) and what they turn into: the options, the reference set, the pose frames."""

import argparse

from ..core.errors import ReferenceSetError
from ..core.formats.bvh import BvhClip, read_bvh
from ..core.formats.table import FORMATS
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
    from ..core.fitting.body_mesh import UNITS, UP_AXES

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


def check_pose_argument(args, kinds):
    """Refuse, before any work is done, an unknown pose name, a pose file or clip that cannot be read and an
    animation for a format of ``kinds`` that holds none. Returns the frames of a pose file, the clip
    (``core.formats.bvh.BvhClip``) of a .bvh, or None; sets ``args.fps`` (walk's default, or the clip's rate)."""
    from ..core.pose.standard import MOTIONS, WALK_FPS, check_pose_name

    if args.pose is None:
        return None
    source = None
    if args.pose.lower().endswith(".bvh"):
        source = read_bvh(args.pose, args.rig, args.fps)
        args.fps = source.motion.fps
    elif args.pose.lower().endswith(".json"):
        from ..core.formats.posed_files import read_pose

        source = read_pose(args.pose)
    else:
        check_pose_name(args.pose)
    args.fps = WALK_FPS if args.fps is None else args.fps
    frames = source.motion.frames if isinstance(source, BvhClip) else len(source or [])
    still = [FORMATS[k] for k in kinds if k in FORMATS and not FORMATS[k].animated]  # (npz: batch's own bundle)
    if still and (args.pose in MOTIONS or frames > 1):
        raise UsageError(
            f"--pose {args.pose} is an animation and a .{still[0].extension} file holds none; write "
            f"{', '.join('.' + f.extension for f in FORMATS.values() if f.animated)}"
        )
    return source


def pose_frames(args, mannequin, source=None, notes=None):
    """The frames of ``--pose`` for ``mannequin`` (None without --pose): ``source`` read by check_pose_argument (a
    pose file's frames, or a clip: retargeted and clamped; what its bones became is said the first time, what was
    clamped and where the feet went is added to ``notes``, or said when there are none), or the standard pose made
    on its joints; ElliMannError naming the joint (and frame) of a pose beyond its limits (a clip's are clamped)."""
    from ..core.pose.kinematics import check_limits, require_joints
    from ..core.pose.standard import standard_motion

    if args.pose is None:
        return None
    if isinstance(source, BvhClip):
        from ..core.pose.clip import clip_onto

        if not getattr(args, "clip_said", False):  # once per command (batch: not per row)
            args.clip_said = True
            for line in source.lines():
                say(f"{PROG} {args.command}: {line}")
            if source.match.stiff_line():
                say(f"{PROG} {args.command}: warning: {source.match.stiff_line()}")
        onto = clip_onto(mannequin, source.motion, source.match, args.keep_on_floor, source.name)
        hint = "; --keep-on-floor holds it on the floor" if not args.keep_on_floor else ""
        clamped = onto.clamp_lines()
        if notes is not None:
            notes.extend(clamped + [onto.floor_line(hint)])
            return onto.poses
        for line in clamped:
            say(f"{PROG} {args.command}: warning: {line}")
        say(f"{PROG} {args.command}: {onto.floor_line(hint)}")
        return onto.poses
    joints = require_joints(mannequin)
    frames = source if source is not None else standard_motion(args.pose, joints, args.fps)
    for index, frame in enumerate(frames):
        check_limits(frame, joints, index if len(frames) > 1 else None)
    return frames


def synthesis_options(args, name=None):
    """The SynthesisOptions of the command line (built once per command)."""
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
