"""``ellimann synth``: one mannequin from five measurements (and any of the extra ones), or from a body mesh's
own measurements (``--from body.obj``), written as .json/.xml (no Blender) or .blend/.glb/.obj (Blender)."""

import json
import sys

from ..core.constants import MEASUREMENT_LABELS, MEASUREMENTS, RANGES
from ..core.errors import ElliMannError
from ..core.formats.table import FORMATS
from ..core.measure.extra import EXTRA_ABSURD_LIMITS, EXTRA_LABELS, EXTRA_MEASUREMENTS
from ..core.synthesis.request import relative_error
from . import arguments, output, skinning, writing
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
    synth.add_argument(
        "--json",
        action="store_true",
        help="print the result as one JSON object on stdout (what was asked, what the pieces measure and, with "
        "--skin, what the skin measures) instead of the line",
    )
    arguments.add_synthesis_options(synth)
    arguments.add_pose_option(synth)
    skinning.add_skin_options(synth)
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
    from ..core.synthesis.synthesize import synthesize_extra

    kind = writing.output_kind(args.output)
    pose_file = arguments.check_pose_argument(args, [kind])
    settings = skinning.skin_settings(args)
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
    skinned = None
    if settings is not None:  # everything that can refuse the skin is checked before it is made
        if args.pose is not None:
            skinning.require_joints_for_skin(mannequin, f"synthesized from the {reference.name} set")
            arguments.pose_frames(args, mannequin, pose_file, notes=[])
        skinning.check_skins_fit(settings, [mannequin])
        skinned = skinning.make_skin(mannequin, settings, args.mode, five, extra)
        mannequin = skinned.mannequin
        measured = {**measured, **skinned.pieces}
    frames = arguments.pose_frames(args, mannequin, pose_file)
    writing.write(
        mannequin,
        [args.output],
        {key: measured[key] for key in MEASUREMENTS},
        args.cushions and kind != "json",
        frames,
        args.fps,
        skin=skinned.skin if skinned else None,
    )
    missed = skinned.misses({**five, **extra}) if skinned else []
    if missed:
        output.say(f"{PROG} synth: warning: {skinning.missed_text(missed, skinned.rounds)}")
    if args.json:
        print(json.dumps(_result(args, mannequin, five, extra, measured, skinned, missed)))
    else:
        output.say(_line(args, mannequin, five, extra, measured, skinned), file=sys.stdout)
    return output.MISSED if (missed if skinned else result.missed) else 0


def _line(args, mannequin, five, extra, measured, skinned):
    """ "wrote OUT: 'NAME' (exact), m_T ... cm, max error ...%"; with a skin, the skin's measurements first and
    the pieces' m_T beside them."""
    posed = f" in pose {args.pose}" if args.pose else ""
    asked = [five[key] for key in MEASUREMENTS]
    if skinned is None:
        achieved = [measured[key] for key in MEASUREMENTS]
        error = relative_error(achieved, asked).max()
        extra_line = ""
        if extra:
            extra_line = "; " + ", ".join(f"{key} {measured[key]:.2f}" for key in EXTRA_MEASUREMENTS) + " cm"
        return (
            f"wrote {args.output}: '{mannequin.name}'{posed} ({args.mode}), m_T {output.format_me(achieved)} cm, "
            f"max error {error:.3f}%{extra_line}"
        )
    on_skin = [skinned.measured[key] for key in MEASUREMENTS]
    error = relative_error(on_skin, asked).max()
    extra_line = "; " + ", ".join(f"{key} {skinned.measured[key]:.2f}" for key in extra) + " cm" if extra else ""
    rounds = f"; {skinned.rounds} round(s) of exact mode on the skin" if skinned.exact else ""
    return (
        f"wrote {args.output}: '{mannequin.name}'{posed} ({args.mode}, {skinning.describe(skinned.skin.settings)}), "
        f"skin {output.format_me(on_skin)} cm, max error {error:.3f}%{extra_line}; pieces' m_T "
        f"{output.format_me(skinned.pieces)} cm{rounds}"
    )


def _result(args, mannequin, five, extra, measured, skinned, missed):
    """The --json object: what was asked, what the pieces measure (m_T, and the extra measurements asked) and, with
    a skin, what the skin measures on its mesh."""
    asked = {**five, **extra}

    def errors(values):
        keys = [key for key in asked if key in values]
        return dict(zip(keys, (float(e) for e in relative_error([values[k] for k in keys], [asked[k] for k in keys]))))

    pieces = {key: measured[key] for key in list(MEASUREMENTS) + [k for k in EXTRA_MEASUREMENTS if k in extra]}
    out = {
        "output": args.output,
        "name": mannequin.name,
        "mode": args.mode,
        "pose": args.pose,
        "requested": asked,
        "measured": pieces,
        "error_pct": errors(pieces),
        "skin": None,
    }
    if skinned is not None:
        skin = skinned.skin
        out["skin"] = {
            **skin.settings.to_dict(),
            "measured": skinned.measured,
            "error_pct": errors(skinned.measured),
            "exact": skinned.exact,
            "rounds": skinned.rounds,
            "converged": (skinned.converged and not missed) if skinned.exact else None,
            "vertices": len(skin.vertices),
            "faces": len(skin.faces),
            "volume_l": skin.volume * 1000.0,
        }
    return json.loads(json.dumps(out), parse_constant=lambda constant: None)  # NaN (not taken): null
