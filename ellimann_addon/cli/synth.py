"""``ellimann synth``: one mannequin from five measurements (and any of the extra ones), or from a body mesh's
own measurements (``--from body.obj``), written as .json/.xml (no Blender) or .blend/.glb/.obj (Blender)."""

import sys

from ..core.constants import MEASUREMENT_LABELS, MEASUREMENTS, RANGES
from ..core.errors import ElliMannError
from ..core.formats.table import FORMATS
from ..core.measure.extra import EXTRA_ABSURD_LIMITS, EXTRA_LABELS, EXTRA_MEASUREMENTS
from ..core.synthesis.request import relative_error
from . import arguments, output, writing
from .output import PROG, UsageError


def add_parser(commands):
    synth = commands.add_parser(
        "synth",
        help="synthesize one mannequin",
        description="Synthesize one mannequin from five measurements (cm), any of the extra "
        "ones (docs/measurements.md), or a body mesh's own (--from).",
    )
    for key in MEASUREMENTS:
        low, high = RANGES[key]
        synth.add_argument(
            f"--{key.lower()}",
            dest=key,
            type=arguments.number,
            metavar="CM",
            help=f"{MEASUREMENT_LABELS[key]} (the female set's reference range {low:g}-{high:g}; "
            "required unless --from)",
        )
    for key in EXTRA_MEASUREMENTS:
        low, high = EXTRA_ABSURD_LIMITS[key]
        synth.add_argument(
            f"--{key.replace('_', '-')}",
            dest=key,
            type=arguments.number,
            metavar="CM",
            help=f"{EXTRA_LABELS[key]} ({low:g}-{high:g}; optional: met in exact mode, otherwise the reference set's)",
        )
    synth.add_argument(
        "--from",
        dest="from_mesh",
        metavar="BODY",
        help="a body mesh (.obj, .ply, .stl; upright A-pose): measure it and synthesize with every "
        "measurement found (a measurement given as an option wins)",
    )
    arguments.add_mesh_axes(synth, "--from")
    synth.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="OUT",
        help="output file: .blend, .glb, .obj, .json (ElliMann's mannequin JSON) or .xml (MJCF, for MuJoCo)",
    )
    synth.add_argument("--name", help="mannequin name (default: 'ElliMann He-Sh-Br-Wa-Hi')")
    arguments.add_synthesis_options(synth)
    arguments.add_pose_option(synth)
    synth.set_defaults(run=run, blender=needs_blender)


def needs_blender(args):
    """What needs Blender in this command (None: nothing)."""
    kind = FORMATS.get(_kind_or_none(args.output))
    return f"writing {args.output}" if kind is not None and kind.needs_blender_for(args.pose is not None) else None


def _kind_or_none(path):
    try:
        return writing.output_kind(path)
    except UsageError:
        return None


def _wanted(args):
    """(the five {key: cm}, the extra ones {key: cm}) from --from's body and the options."""
    found = {}
    if args.from_mesh:
        from .measure import measure_mesh_file

        found, problems = measure_mesh_file(args.from_mesh, args)
        if not found:
            raise UsageError(f"{args.from_mesh}: {problems[0]}")
        for problem in problems:
            output.say(f"{PROG} synth: warning: {args.from_mesh}: {problem}")
        output.say(
            f"{args.from_mesh}: measured " + ", ".join(f"{key} {value:.2f}" for key, value in found.items()),
            file=sys.stdout,
        )
    given = {key: getattr(args, key) for key in MEASUREMENTS + EXTRA_MEASUREMENTS if getattr(args, key) is not None}
    wanted = {**found, **given}
    missing = [key for key in MEASUREMENTS if key not in wanted]
    if missing:
        where = f" ({args.from_mesh} gave none)" if args.from_mesh else ""
        raise UsageError(f"missing {', '.join('--' + key.lower() for key in missing)}{where}")
    return (
        {key: wanted[key] for key in MEASUREMENTS},
        {key: wanted[key] for key in EXTRA_MEASUREMENTS if key in wanted},
    )


def run(args):
    from ..core.synthesis.synthesize import synthesize_extra

    kind = writing.output_kind(args.output)
    pose_file = arguments.check_pose_argument(args, [kind])
    five, extra = _wanted(args)
    reference = arguments.references(args)
    try:  # the request is checked here, once, before any work (its warnings come back with the result)
        options = arguments.synthesis_options(args, args.name)
        result = synthesize_extra(reference, five, extra, options, measure_extra=False)
    except ElliMannError as error:
        raise UsageError(output.one_line(error)) from None
    mannequin, measured = result.mannequin, result.measured
    for warning in result.warnings:
        output.say(f"{PROG} synth: warning: {warning}")
    frames = arguments.pose_frames(args, mannequin, pose_file)
    writing.write(
        mannequin,
        [args.output],
        {key: measured[key] for key in MEASUREMENTS},
        args.cushions and kind != "json",
        frames,
        args.fps,
    )
    achieved = [measured[key] for key in MEASUREMENTS]
    error = relative_error(achieved, [five[key] for key in MEASUREMENTS]).max()
    posed = f" in pose {args.pose}" if args.pose else ""
    extra_line = "; " + ", ".join(f"{key} {measured[key]:.2f}" for key in EXTRA_MEASUREMENTS) + " cm" if extra else ""
    output.say(
        f"wrote {args.output}: '{mannequin.name}'{posed} ({args.mode}), m_T {output.format_me(achieved)} cm, "
        f"max error {error:.3f}%{extra_line}",
        file=sys.stdout,
    )
    return output.MISSED if result.missed else 0
