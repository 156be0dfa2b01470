"""``ellimann sizes``: a measurement file people have (a Seamly2D / Valentina .vit or multisize .vst, a FreeSewing
set, a size chart: ``core.sizing``) made into one avatar per person or size, each meeting its row on its skin, with a
report in the file's own unit (``sizes_report``) and a line-up picture of the run in size order (Blender).

Every row is a job (``core.job``): its five (a missing one predicted from the survey) and its extra measurements, the
skin on (auto: the body skin where the set has bodies), written in every ``--format``; a row that fails (a bad value,
a size outside the set's range, increments that make a girth negative) is said in one line and reported, and the run
goes on. numpy alone writes .json, .obj and .xml; .fbx and .glb need Blender, refused before any work without it."""

import contextlib
import os
import re
import sys

from ..core.errors import ElliMannError
from ..core.formats.table import format_named, listing
from ..core.measurements import MEASUREMENTS
from ..core.settings import AVATAR_POSES, SKIN
from . import arguments, avatar_options, jobs, output, sizes_report, skin_options, writing
from .output import PROG, UsageError

DEFAULT_FORMATS = "json,obj"
SEXES = ("female", "male")
FILE_NAME = re.compile(r"[^A-Za-z0-9._-]+")


def add_parser(commands):
    sizes = commands.add_parser(
        "sizes",
        help="avatars from a measurement file: a .vit, a multisize .vst, a FreeSewing set or a size chart",
        description="One avatar per person or size of a measurement file (Seamly2D/Valentina .vit or .vst, a "
        "FreeSewing .json set, a .csv size chart; docs/formats/measurement_files.md), each meeting its row on its "
        "skin, written to DIR with DIR/report.csv and report.md (requested vs measured per size and measurement, "
        "in the file's own unit) and DIR/lineup.png (Blender). A row that fails is said and reported, the rest go "
        "on; the exit code is 1 if a row failed, 3 if a skin missed its row.",
    )
    sizes.add_argument("file", metavar="FILE", help="a .vit, .vst, FreeSewing .json or size chart .csv")
    sizes.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")
    sizes.add_argument(
        "--format",
        default=DEFAULT_FORMATS,
        help=f"comma-separated output formats among {listing(what='name')} (default {DEFAULT_FORMATS}: the "
        "mannequin with how its skin was made, and the skin alone, Y up); fbx (an avatar for garment tools) and "
        "glb need Blender",
    )
    arguments.add_references(
        sizes,
        "the reference set to make them on (default: female, or male for a file of a man)",
        shipped="female, male, female-fine or male-fine",
    )
    sizes.add_argument(
        "--sex", choices=SEXES, help="the person's sex when the file does not say it (default: female, and said)"
    )
    sizes.add_argument(
        "--stats",
        metavar="FILE",
        help="survey statistics (a name or a file, docs/population.md) a missing one of the five is predicted from "
        "(default: the shipped survey of the sex: ANSUR II's women; none of men is shipped)",
    )
    sizes.add_argument(
        "--extrapolate",
        action="store_true",
        help="make a row outside the reference set's ranges anyway (a warning; exact mode reaches some way beyond)",
    )
    sizes.add_argument(
        "--pose",
        choices=AVATAR_POSES,
        default=AVATAR_POSES[0],
        help="the avatars' pose: a_pose (default: the bodies' own, where the measurements are taken) or t_pose "
        "(arms out level; the .fbx's rest pose, the other formats posed)",
    )
    avatar_options.add_avatar_options(sizes)
    sizes.add_argument(
        "--sizes",
        metavar="LIST",
        help="a multisize table (.vst): the sizes to make, comma-separated in the file's unit (default: its min to "
        "max by step)",
    )
    sizes.add_argument(
        "--heights",
        metavar="LIST",
        help="a multisize table (.vst): the heights to make each size at (default: its base height)",
    )
    low, high = SKIN["skin_voxel"].limits
    for name, option in SKIN.items():  # the skin is always on: its options (synth's, without --skin)
        text = option.help.format(default=option.default, low=low, high=high)
        if option.choices:
            sizes.add_argument(skin_options.flag(name), choices=option.values, default=None, help=text)
        else:
            metavar = skin_options.METAVARS.get(name)
            sizes.add_argument(skin_options.flag(name), type=arguments.number, metavar=metavar, help=text)
    sizes.add_argument("--no-picture", dest="picture", action="store_false", help="skip the line-up picture")
    arguments.add_verbose(sizes)
    sizes.set_defaults(run=run, blender=lambda args: None)  # the jobs check their files; the picture is optional


def parse_formats(text):
    """The rows of ``core.formats.table`` that ``--format`` names, in order (no duplicates)."""
    words = [word.strip() for word in text.split(",") if word.strip()]
    found = [format_named(word) for word in words]
    if not words or None in found:
        raise UsageError(f"--format takes a comma-separated list of {listing(what='name')}, got {text!r}")
    return list(dict.fromkeys(found))


def parse_numbers(text, option):
    """The numbers of a comma-separated ``--sizes`` / ``--heights`` (None when not given)."""
    if text is None:
        return None
    try:
        values = [float(word) for word in text.split(",") if word.strip()]
    except ValueError:
        raise UsageError(f"{option} takes comma-separated numbers in the file's unit, got {text!r}") from None
    if not values or any(not value > 0 for value in values):
        raise UsageError(f"{option} takes comma-separated positive numbers in the file's unit, got {text!r}")
    return values


def read_file(args):
    """(MeasurementFile, ReferenceSet) of the command line: the file read once its set is known (the file's sex
    chooses the default set: male -> the male set), every row checked against that set's ranges."""
    from ..core.sizing.readers import read_measurement_file

    path = args.file
    if not os.path.isfile(path):
        raise UsageError(f"{path}: no such file")
    options = dict(statistics=args.stats, extrapolate=args.extrapolate)
    is_vst = path.lower().endswith(".vst")
    for option, name in ((args.sizes, "--sizes"), (args.heights, "--heights")):
        if option is not None and not is_vst:
            raise UsageError(f"{name} chooses the run of a multisize table (.vst); {path} is not one")
    if is_vst:
        options.update(sizes=parse_numbers(args.sizes, "--sizes"), heights=parse_numbers(args.heights, "--heights"))
    chosen = args.references
    sex = args.sex
    if chosen is None:  # the file's sex chooses the set: read once without the range check to learn it
        sex = read_measurement_file(path, sex=sex, ranges_by_set={}, **options).sex or sex
        chosen = "male" if sex == "male" else "female"
    elif sex is None and str(chosen).startswith("male"):
        sex = "male"  # a shipped male set: a man's file, unless it says otherwise
    reference = arguments.references(args, chosen)
    ranges = {reference.name: reference.ranges}  # the set the rows are made on: its ranges (cm)
    return read_measurement_file(path, sex=sex, ranges_by_set=ranges, **options), reference


def file_names(rows):
    """A file name for each row (its label made safe; a repeated one numbered)."""
    names, seen = [], set()
    for index, row in enumerate(rows):
        stem = FILE_NAME.sub("_", row.label).strip("._") or f"row{index + 1}"
        name, count = stem, 1
        while name.casefold() in seen:
            count += 1
            name = f"{stem}-{count}"
        seen.add(name.casefold())
        names.append(name)
    return names


def run(args):
    from ..core.job.request import PoseAsk, Request
    from ..core.synthesis.options import SynthesisOptions

    formats = parse_formats(args.format)
    args.skin = True  # the skin is always on: its options are the skin's
    skin = skin_options.skin_settings(args)
    pose = PoseAsk("t_pose") if args.pose == "t_pose" else None
    avatar = avatar_options.avatar_settings(args, [f"NAME.{kind.extension}" for kind in formats])
    read, reference = read_file(args)
    if not read.rows:
        raise UsageError(f"{args.file}: holds no person or size")
    out = args.output

    def outputs(name):
        return tuple(os.path.join(out, f"{name}.{kind.extension}") for kind in formats)

    # the whole command checked once (its formats, Blender, the skin, the avatar) before anything is written
    command = jobs.checked(
        Request(
            dict(zip(MEASUREMENTS, reference.measurements[0])),
            reference,
            skin=skin,
            pose=pose,
            outputs=outputs("NAME"),
            avatar=avatar,
        ),
        blender_use=lambda kind: f"--format {kind.name}",
    )
    writing.output_folder(out, "sizes")
    for note in read.notes:
        output.say(f"{PROG} sizes: note: {note}")
    stem = os.path.splitext(os.path.basename(args.file))[0]
    names = file_names(read.rows)
    progress = output.Progress(len(read.rows), "sizes", quiet=args.quiet)
    done = []
    for row, name in zip(read.rows, names):
        made = sizes_report.Made(row, name)
        done.append(made)
        if not row.ok:
            made.fail(row.error.replace("or allow extrapolation", "or allow extrapolation (--extrapolate)"))
        else:
            told = []
            request = Request(
                row.request(),
                reference,
                row.extra(),
                SynthesisOptions(name=f"{stem} {row.label}"),
                skin=skin,
                pose=pose,
                outputs=outputs(name),
                avatar=None if avatar is None else avatar_replace(avatar, told.append),
            )
            try:
                make_row(request, made, told)
            except (ElliMannError, OSError, RuntimeError) as error:  # RuntimeError: a Blender writer's
                made.fail(f"{read.path} size {row.label!r}: {output.one_line(error)}")
                remove_outputs(request.outputs)
            except KeyboardInterrupt:  # the sizes done so far keep their files and are reported; this one has none
                remove_outputs(request.outputs)
                done.pop()
                progress.done()
                report = write_report(read, reference, command.skin, done, formats, out, None, interrupted=True)
                output.say(
                    f"{PROG} sizes: interrupted: {report.count('ok', 'missed')} of {len(read.rows)} sizes done, "
                    f"report {os.path.join(out, 'report.md')}"
                )
                return output.INTERRUPTED
        for line in made.lines():
            output.say(f"{PROG} sizes: {line}")
        progress.step(row.label)
    progress.done()
    report = write_report(read, reference, command.skin, done, formats, out, lineup(args, out, done))
    failed, missed = report.count("error"), report.count("missed")
    output.say(
        f"{PROG} sizes: {report.count('ok', 'missed')} of {len(done)} avatars written to {out} ({reference.name} set, "
        f"{skin_options.describe(report.skin_settings())}); worst difference {report.worst_text()}; report "
        f"{os.path.join(out, 'report.md')}",
        file=sys.stdout,
    )
    if failed:
        output.say(f"{PROG} sizes: error: {failed} row(s) failed; see {os.path.join(out, 'report.md')}")
        return 1
    return output.MISSED if missed else 0


def write_report(read, reference, skin, done, formats, out, picture, interrupted=False):
    """The run's report.csv and report.md in ``out``, of the sizes ``done`` (sizes_report.Made)."""
    report = sizes_report.Report(read, reference, skin, done, formats)
    report.picture, report.interrupted = picture, interrupted
    writing.write_text(os.path.join(out, "report.csv"), report.csv())
    writing.write_text(os.path.join(out, "report.md"), report.markdown())
    return report


def avatar_replace(avatar, told):
    import dataclasses

    return dataclasses.replace(avatar, told=told)


def remove_outputs(paths):
    """Remove the files of a row that failed, halfway or not (its .json written, its .fbx refused; or an earlier
    run's, which this run was to replace): a report's failed row has no files."""
    for path in paths:
        with contextlib.suppress(OSError):
            os.remove(path)


def make_row(request, made, told):
    """Make one row's job and write its files; ``made`` (sizes_report.Made) keeps what came of it."""
    from ..core.job.make import make

    job = jobs.checked(request)
    result = make(job)
    writing.write(result, job.formats, False, job.avatar)
    made.done(result, list(job.formats), told)


def lineup(args, out, done):
    """DIR/lineup.png: the skins of the rows made, side by side in the run's order, labelled by size (Blender);
    None (and said) when it is skipped."""
    made = [m for m in done if m.result is not None]
    if not args.picture or not made:
        return None
    if not writing.blender_available():
        output.say(f"{PROG} sizes: no line-up picture: it needs Blender (the bpy module); files and report are written")
        return None
    path = os.path.join(out, "lineup.png")
    try:  # the avatars and the report matter more than their picture: a picture that fails is said, not fatal
        writing.blender_module("the line-up picture")
        from ..blender.services.render import render_lineup

        with writing.writing(path):
            render_lineup(
                [m.result.mannequin for m in made],
                path,
                labels=[m.row.label for m in made],
                skins=[m.result.skin.skin if m.result.skin is not None else None for m in made],
                width=max(800, 260 * len(made)),
            )
    except (ElliMannError, RuntimeError) as error:
        output.say(f"{PROG} sizes: warning: no line-up picture: {output.one_line(error)}")
        return None
    return path
