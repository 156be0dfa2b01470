"""``ellimann pose IN.json --pose NAME -o OUT``: an existing mannequin (with joints) written in a pose."""

import sys

from ..core.errors import MannequinError
from ..core.formats.table import FORMATS, format_of
from . import arguments, jobs, output, skin_options, writing
from .output import PROG, UsageError


def add_parser(commands):
    pose = commands.add_parser(
        "pose",
        help="write a mannequin in a pose",
        description="Write a mannequin (a .json with joints) in a standard pose or a pose "
        "file; its measurements stay the rest pose's.",
    )
    pose.add_argument("input", metavar="IN.json", help="the mannequin (ElliMann's JSON, with joints)")
    pose.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="OUT",
        help="output file: .json (rest mannequin, joints and the pose), .xml (MJCF: an articulated "
        "body, the pose as keyframes), .obj (the posed pieces), .glb or .blend (Blender's rig)",
    )
    pose.add_argument(
        "--cushions", action="store_true", help="cushions instead of their ellipsoids (split at the joints they cross)"
    )
    arguments.add_verbose(pose)
    arguments.add_pose_option(pose)
    skin_options.add_skin_options(pose, rebuilt=True)
    pose.set_defaults(run=run, blender=lambda args: None)  # the job checks its file


def run(args):
    from ..core.job.make import make
    from ..core.job.request import Request
    from ..core.mannequin.model import Mannequin

    if args.pose is None:
        raise UsageError(f"--pose is required: one of the standard poses or a pose .json (see {PROG} pose --help)")
    if format_of(args.input) is not FORMATS["json"]:
        raise UsageError(f"IN must be a mannequin .json file, got {args.input!r}")
    try:
        mannequin = Mannequin.load(args.input)
    except MannequinError as error:
        raise UsageError(f"{args.input}: {error}") from None
    settings = skin_options.skin_settings(args, mannequin.skin)
    request = Request(
        skin=settings,
        pose=arguments.pose_ask(args),
        outputs=(args.output,),
        cushions=args.cushions,
        mannequin=mannequin,
    )
    job = jobs.checked(request)
    arguments.say_clip(args, job.pose)
    recorded = None
    if settings is not None and mannequin.skin:
        from ..core.mannequin.skin_record import SkinSettings  # the skin's code, loaded only when a skin is asked

        recorded = SkinSettings.from_dict(mannequin.skin)
    if recorded and recorded != settings:
        output.say(
            f"{PROG} pose: {args.input} records its skin at {skin_options.describe(recorded)}; made at "
            f"{skin_options.describe(settings)} as asked (another voxel or blend measures a little differently)"
        )
    result = make(job)  # the skin made again from the pieces, as the file records (the same pieces: the same skin)
    for warning in result.warnings:
        output.say(f"{PROG} pose: warning: {warning}")
    for note in result.notes:
        output.say(f"{PROG} pose: {note}")
    writing.write(result, job.formats, args.cushions, job.avatar)
    frames = result.frames
    count = f" ({len(frames)} frames)" if len(frames) > 1 else ""
    made = f", with its {skin_options.describe(settings)}" if settings is not None else ""
    output.say(f"wrote {args.output}: '{mannequin.name}' in pose {args.pose}{count}{made}", file=sys.stdout)
    return 0
