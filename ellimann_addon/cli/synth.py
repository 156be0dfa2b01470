"""``ellimann synth``: one mannequin from five measurements, written as .json/.xml (no Blender) or
.blend/.glb/.obj (Blender)."""

import sys

from ..core.constants import MEASUREMENT_LABELS, MEASUREMENTS, RANGES
from ..core.formats import FORMATS
from ..core.measure import as_dict
from ..core.request import relative_error, validate_request
from . import common
from .common import PROG, UsageError


def add_parser(commands):
    synth = commands.add_parser("synth", help="synthesize one mannequin",
                                description="Synthesize one mannequin from five measurements (cm).")
    for key in MEASUREMENTS:
        low, high = RANGES[key]
        synth.add_argument(f"--{key.lower()}", dest=key, type=common.number, required=True, metavar="CM",
                           help=f"{MEASUREMENT_LABELS[key]} (the female set's reference range {low:g}-{high:g})")
    synth.add_argument("-o", "--output", required=True, metavar="OUT",
                       help="output file: .blend, .glb, .obj, .json (ElliMann's mannequin JSON) or .xml (MJCF, "
                            "for MuJoCo)")
    synth.add_argument("--name", help="mannequin name (default: 'ElliMann He-Sh-Br-Wa-Hi')")
    common.add_synthesis_options(synth)
    common.add_pose_option(synth)
    synth.set_defaults(run=run, blender=needs_blender)


def needs_blender(args):
    """What needs Blender in this command (None: nothing)."""
    kind = FORMATS.get(_kind_or_none(args.output))
    return f"writing {args.output}" if kind is not None and kind.needs_blender_for(args.pose is not None) else None


def _kind_or_none(path):
    try:
        return common.output_kind(path)
    except UsageError:
        return None


def run(args):
    from ..core.synthesis import synthesize_batch

    kind = common.output_kind(args.output)
    pose_file = common.check_pose_argument(args, [kind])
    request = [getattr(args, key) for key in MEASUREMENTS]
    reference = common.references(args)
    warnings = validate_request(request, reference.ranges, reference.absurd_limits)
    options = common.synthesis_options(args, args.name)
    result = synthesize_batch(reference, [request], options)
    mannequin, measured = result.mannequin(0, options.name), as_dict(result.measured[0])
    misses = common.misses(result.measured[0], request) if args.mode == "exact" else []
    for warning in warnings + ([common.missed_text(misses)] if misses else []):
        common.say(f"{PROG} synth: warning: {warning}")
    frames = common.pose_frames(args, mannequin, pose_file)
    common.write(mannequin, [args.output], measured, args.cushions and kind != "json", frames, args.fps)
    error = relative_error(result.measured[0], request).max()
    posed = f" in pose {args.pose}" if args.pose else ""
    common.say(f"wrote {args.output}: '{mannequin.name}'{posed} ({args.mode}), m_T "
               f"{common.format_me(measured.values())} cm, max error {error:.3f}%", file=sys.stdout)
    return common.MISSED if misses else 0
