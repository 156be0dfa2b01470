"""``ellimann synth``: one mannequin from five measurements (and any of the extra ones), or from a body mesh's
own measurements (``--from body.obj``), written as .json/.xml (no Blender) or .blend/.glb/.obj (Blender)."""

import json
import sys

from ..core.constants import RANGES
from ..core.formats.table import listing
from ..core.measurements import (
    EXTRA_ABSURD_LIMITS,
    EXTRA_MEASUREMENTS,
    MEASUREMENT_LABELS,
    MEASUREMENTS,
    measurement_line,
)
from ..core.synthesis.request import relative_error
from . import arguments, avatar_options, jobs, output, skin_options, writing
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
            help=f"{MEASUREMENT_LABELS[key]} ({low:g}-{high:g}; optional: met in exact mode, otherwise the "
            "reference set's)",
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
        help=f"output file: {listing()} (the format by its extension)",
    )
    synth.add_argument("--name", help="mannequin name (default: 'ElliMann He-Sh-Br-Wa-Hi')")
    synth.add_argument(
        "--json",
        action="store_true",
        help="print the result as one JSON object on stdout (what was asked, what the pieces measure and, with "
        "--skin, what the skin measures) instead of the line",
    )
    arguments.add_synthesis_options(synth)
    arguments.add_pose_option(synth)
    skin_options.add_skin_options(synth)
    avatar_options.add_avatar_options(synth)
    synth.set_defaults(run=run, blender=lambda args: None)  # the job checks its files


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
            file=sys.stderr if args.json else sys.stdout,  # --json: stdout holds the JSON alone
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
    from ..core.job.make import make
    from ..core.job.request import Request

    five, extra = _wanted(args)
    request = Request(
        five,
        arguments.references(args),
        extra,
        arguments.synthesis_options(args, args.name),
        args.cushions,
        skin_options.skin_settings(args),
        arguments.pose_ask(args),
        (args.output,),
        avatar=avatar_options.avatar_settings(args, (args.output,)),
    )
    job = jobs.checked(request)  # everything that could refuse it, before any work
    arguments.say_clip(args, job.pose)
    result = make(job)
    for warning in result.warnings + [result.missed_text()][: bool(result.missed)]:
        output.say(f"{PROG} synth: warning: {warning}")
    for note in result.notes:
        output.say(f"{PROG} synth: {note}")
    writing.write(result, job.formats, args.cushions, job.avatar)
    if args.json:
        print(json.dumps(_result(args, result)))
    else:
        output.say(_line(args, result), file=sys.stdout)
    return output.MISSED if result.missed else 0


def _line(args, result):
    """ "wrote OUT: 'NAME' (exact), m_T ... cm, max error ...%"; with a skin, the skin's measurements first and
    the pieces' m_T beside them."""
    posed = f" in pose {args.pose}" if args.pose else ""
    asked = [result.request[key] for key in MEASUREMENTS]
    extra = [key for key in EXTRA_MEASUREMENTS if key in result.request]
    shown = result.shown()
    error = relative_error([shown[key] for key in MEASUREMENTS], asked).max()
    extra_line = f"; {measurement_line(shown, extra)} cm" if extra else ""
    name = result.mannequin.name
    if result.skin is None:
        return (
            f"wrote {args.output}: '{name}'{posed} ({args.mode}), m_T {measurement_line(result.five)} cm, "
            f"max error {error:.3f}%{extra_line}"
        )
    skin = result.skin
    rounds = f"; {skin.rounds} round(s) of exact mode on the skin" if skin.exact else ""
    return (
        f"wrote {args.output}: '{name}'{posed} ({args.mode}, {skin_options.describe(skin.settings)}), "
        f"skin {measurement_line(shown, MEASUREMENTS)} cm, max error {error:.3f}%{extra_line}; "
        f"pieces' m_T {measurement_line(result.five)} cm{rounds}"
    )


def _result(args, result):
    """The --json object: what was asked, what the pieces measure (m_T, and the extra measurements asked) and, with
    a skin, what the skin measures on its mesh."""
    asked = result.request

    def errors(values):
        keys = [key for key in asked if key in values]
        return dict(zip(keys, (float(e) for e in relative_error([values[k] for k in keys], [asked[k] for k in keys]))))

    pieces = {key: result.measured[key] for key in asked}
    out = {
        "output": args.output,
        "name": result.mannequin.name,
        "mode": args.mode,
        "pose": args.pose,
        "requested": asked,
        "measured": pieces,
        "error_pct": errors(pieces),
        "skin": None,
    }
    if result.skin is not None:
        skin = result.skin
        out["skin"] = {
            **skin.skin.record(),
            "measured": skin.measured,
            "error_pct": errors(skin.measured),
            "exact": skin.exact,
            "rounds": skin.rounds,
            "converged": (skin.converged and not result.missed) if skin.exact else None,
            "vertices": len(skin.skin.vertices),
            "faces": len(skin.skin.faces),
            "volume_l": skin.skin.volume * 1000.0,
        }
    return json.loads(json.dumps(out), parse_constant=lambda constant: None)  # NaN (not taken): null
