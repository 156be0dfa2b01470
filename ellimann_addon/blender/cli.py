"""The ElliMann command line: one ``main(argv) -> int`` behind two entry points.

- ``blender --background --command ellimann …`` (registered with ``bpy.utils.register_cli_command``)
- ``python -m ellimann_addon …`` (with the ``bpy`` module installed)

Subcommands: ``synth`` (one mannequin), ``batch`` (a CSV of measurements), ``measure`` (m_T of a
file), ``demo`` (the paper's Table 2.5 mannequins with a report and a line-up picture) and
``drape`` (a garment on a mannequin with Blender's cloth simulation).
Blender is imported only when a .blend/.glb/.obj file, a drape or a picture is involved, so
``--help`` and JSON/MJCF work start at once. What Blender prints is captured (``chatter``) and shown
only with ``--verbose``. User mistakes end with a one-line reason and a non-zero exit code: 1 for
bad input or a failed row, 2 for a malformed command line, 3 when exact mode misses a request (the
files are written), 130 when interrupted (Ctrl-C).
"""

import argparse
import contextlib
import csv
import dataclasses
import io
import json
import math
import os
import re
import sys
import tempfile
import time

from ..core.constants import CM_PER_M, MEASUREMENT_LABELS, MEASUREMENTS, RANGES, TABLE_2_5
from ..core.ellipsoid import bounds
from ..core.errors import ElliMannError, MannequinError, MeasurementError, ReferenceSetError
from ..core.files import atomic_write_text, clean_stale_temporaries, incomplete
from ..core.garments import BUILDERS as GARMENTS
from ..core.garments import EDGE_RANGE
from ..core.mannequin import Mannequin
from ..core.measure import as_dict
from ..core.synthesis import (
    DEFAULT_NORMALIZE,
    DEFAULT_POWER,
    EXACT_TOLERANCE,
    METRICS,
    MODES,
    NORMALIZATIONS,
    PAPER_NORMALIZE,
    load_reference_set,
    relative_error,
    synthesize_batch,
    validate_request,
)
from ..core.writers import EXTENSIONS, core_format, write_core_file
from .services.chatter import blender_output, program

PROG = "ellimann"
FORMATS = ("blend", "glb", "obj", "json", "mjcf")  # --format names; the file extension is the name but for mjcf
NAME_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,99}$")
CHUNK = 256  # rows synthesized per core batch
MISSED = 3  # exit code: written, but exact mode missed a requested measurement by more than its tolerance
INTERRUPTED = 130  # exit code after Ctrl-C, as shells report SIGINT


class UsageError(ElliMannError):
    """A mistake on the command line or in an input file, reported in one line."""


# ------------------------------------------------------------------------------------------------ parser


def _number(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    return value


def _add_verbose(parser):
    parser.add_argument("-v", "--verbose", action="store_true",
                        help="also show what Blender prints (on stderr); without it only ElliMann's lines show")


def _add_synthesis_options(parser):
    _add_verbose(parser)
    parser.add_argument("--mode", choices=MODES, default="exact",
                        help="exact (default): refine until m_T matches the request; idw: the paper's "
                             "interpolation alone")
    parser.add_argument("--metric", choices=METRICS, default="raw",
                        help="IDW distance: raw cm as in the paper (default) or normalized by the ranges L")
    parser.add_argument("--power", type=_number, default=DEFAULT_POWER, help="IDW power p (default 2)")
    parser.add_argument("--normalize", choices=NORMALIZATIONS, default=DEFAULT_NORMALIZE,
                        help="what IDW averages: proportional (default): each part's heights in proportion to He "
                             "and widths to its own measurement; height: heights only; none: the RMs' geometry "
                             "as it is (the paper)")
    parser.add_argument("--cushions", action="store_true",
                        help="cushions (convex hulls of the cushion pairs) instead of their ellipsoids: shown in "
                             ".blend/.glb/.obj outputs, convex mesh geoms in MJCF")
    parser.add_argument("--references", metavar="DIR",
                        help="folder with the five Reference Mannequin .json files (default: the shipped "
                             "reference_blends/)")


def build_parser():
    parser = argparse.ArgumentParser(prog=PROG, description="ElliMann: measurement-driven mannequins from "
                                     "convex ellipsoids and cushions (measurements in cm).")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    synth = commands.add_parser("synth", help="synthesize one mannequin",
                                description="Synthesize one mannequin from five measurements (cm).")
    for key in MEASUREMENTS:
        low, high = RANGES[key]
        synth.add_argument(f"--{key.lower()}", dest=key, type=_number, required=True, metavar="CM",
                           help=f"{MEASUREMENT_LABELS[key]} (reference range {low:g}-{high:g})")
    synth.add_argument("-o", "--output", required=True, metavar="OUT",
                       help="output file: .blend, .glb, .obj, .json (ElliMann's mannequin JSON) or .xml (MJCF, "
                            "for MuJoCo)")
    synth.add_argument("--name", help="mannequin name (default: 'ElliMann He-Sh-Br-Wa-Hi')")
    _add_synthesis_options(synth)
    synth.set_defaults(run=run_synth)

    batch = commands.add_parser("batch", help="synthesize every row of a CSV",
                                description="One mannequin per CSV row. The header names the columns "
                                            "He,Sh,Br,Wa,Hi (cm) and optionally name. Writes the files and "
                                            "DIR/report.csv (requested vs measured), row by row into "
                                            "DIR/report.partial.csv while it runs. Bad or failed rows are "
                                            "reported and skipped; the exit code is 1 if any row failed, 3 if "
                                            "exact mode missed a row's request, 130 if interrupted.")
    batch.add_argument("csv", metavar="MEASUREMENTS.csv")
    batch.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")
    batch.add_argument("--format", default="json",
                       help="comma-separated output formats among blend,glb,obj,json,mjcf (default json; mjcf "
                            "writes NAME.xml)")
    batch.add_argument("--shard", metavar="I/N",
                       help="process only rows I, I+N, I+2N… (I from 1 to N), for a render farm; the report "
                            "is DIR/report-I-of-N.csv")
    batch.add_argument("--resume", action="store_true",
                       help="skip rows whose files (every --format) are already in DIR and whole, e.g. after an "
                            "interrupted run with the same CSV and options; without it every row is written again")
    _add_synthesis_options(batch)
    batch.set_defaults(run=run_batch)

    measure = commands.add_parser("measure", help="m_T of a mannequin file",
                                  description="Tailor measurements (m_T) of a .json or .blend mannequin, in cm.")
    measure.add_argument("file", metavar="FILE")
    measure.add_argument("--json", action="store_true",
                         help='print exactly {"He": …, "Sh": …, "Br": …, "Wa": …, "Hi": …}')
    measure.add_argument("--collection", help="the mannequin collection to measure in a .blend holding several")
    _add_verbose(measure)
    measure.set_defaults(run=run_measure)

    demo = commands.add_parser("demo", help="the paper's ten Table 2.5 mannequins, a report and a line-up",
                               description="Synthesize the ten mannequins of the paper's Table 2.5 into DIR: "
                                           ".blend and .json files, report.csv, report.md and lineup.png.")
    demo.add_argument("-o", "--output", required=True, metavar="DIR")
    demo.add_argument("--no-picture", dest="picture", action="store_false", help="skip the line-up render")
    _add_synthesis_options(demo)
    demo.set_defaults(run=run_demo)

    drape = commands.add_parser("drape", help="drape a garment on a mannequin with Blender's cloth simulation",
                                description="Build a garment sized from the mannequin's m_T, drape it with "
                                            "Blender cloth (the mannequin's convex pieces as colliders), bake the "
                                            "frames and save the scene as a .blend; prints the fit (garment-to-"
                                            "body distances, vertices inside the body). Defaults are the Drape "
                                            "panel's (DrapeSettings).",
                                formatter_class=_DrapeHelp)
    drape.add_argument("mannequin", metavar="MANNEQUIN", help="a .json or .blend mannequin")
    drape.add_argument("--garment", choices=tuple(GARMENTS), default="tube_dress",
                       help="tube_dress (strapless, pinned at the top edge; default) or t_shirt (sewn at the "
                            "shoulders and armholes)")
    drape.add_argument("--frames", type=int, help="frames to simulate (default {frames}, at 24 fps)")
    drape.add_argument("--cushions", action=argparse.BooleanOptionalAction,
                       help="collide with the cushions and the ellipsoids not in one; --no-cushions: with every "
                            "ellipsoid (default: {cushions})")
    drape.add_argument("--edge", type=_number, metavar="CM",
                       help="edge length of the cloth mesh in cm (default {edge_cm:g}; smaller is finer and slower)")
    drape.add_argument("--collection", help="the mannequin collection in a .blend holding several (.blend only)")
    drape.add_argument("-o", "--output", required=True, metavar="OUT.blend")
    drape.add_argument("--render", metavar="OUT.png", help="also a Workbench picture of the last frame")
    _add_verbose(drape)
    drape.set_defaults(run=run_drape)
    return parser


class _DrapeHelp(argparse.HelpFormatter):
    """Fills the drape defaults into ``drape --help`` from DrapeSettings, the one place they are set.

    DrapeSettings lives in the bpy layer, so only ``drape --help`` loads Blender, not ``--help``.
    """

    def _get_help_string(self, action):
        text = super()._get_help_string(action)
        return text.format(**_drape_defaults()) if text and "{" in text else text


def _drape_defaults():
    from .drape import DrapeSettings

    defaults = DrapeSettings()
    return {"frames": defaults.frames, "edge_cm": defaults.edge * CM_PER_M,
            "cushions": "cushions" if defaults.cushions else "every ellipsoid"}


def main(argv=None):
    """Run the CLI; returns the exit code (0 success, 1 bad input or failed rows, 2 bad command line,
    3 exact mode missed a request, 130 interrupted)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:  # argparse has printed usage or help
        return int(exit_.code or 0)
    try:
        with program(show=args.verbose):
            return args.run(args)
    except (ElliMannError, OSError) as error:
        _say(f"{PROG} {args.command}: error: {_one_line(error)}")
        return 1
    except KeyboardInterrupt:
        _say(f"{PROG} {args.command}: interrupted")
        return INTERRUPTED


def _one_line(error):
    if isinstance(error, OSError) and error.filename:
        return f"{error.strerror or error}: {error.filename}"
    return " ".join(str(error).split())


_UNPRINTABLE = re.compile(r"[\x00-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028-\u202e\u2066-\u2069]")


def printable(text):
    """``text`` with control characters (terminal escapes, carriage returns, bidi overrides) as \\x1b, \\n…"""
    return _UNPRINTABLE.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), str(text))


def _say(text, file=None, end="\n"):
    """Print one of ElliMann's lines (stderr unless ``file``), escaping what a terminal would act on."""
    print(printable(text), file=file or sys.stderr, end=end, flush=True)


# ------------------------------------------------------------------------------------------------ helpers


def _ensure_registered():
    """Import bpy; under ``python -m`` register the add-on once so ElliMann's properties exist."""
    with blender_output():
        import bpy

        if not hasattr(bpy.types.Collection, "ellimann"):
            from .. import register

            register()
    return bpy


def _output_kind(path):
    extension = os.path.splitext(path)[1].lower().lstrip(".")
    kind = next((k for k in FORMATS if _extension(k) == extension), None)
    if kind is None:
        raise UsageError(f"OUT must end in .blend, .glb, .obj, .json or .xml (MJCF), got {path!r}")
    return kind


def _extension(kind):
    return EXTENSIONS.get(kind, kind)


def _references(args):
    try:
        return load_reference_set(args.references)
    except ReferenceSetError as error:
        if args.references:
            raise
        raise UsageError(f"{error} (the shipped Reference Mannequins; use --references DIR for others)") from None


def _format_me(values):
    return ", ".join(f"{key} {value:.2f}" for key, value in zip(MEASUREMENTS, values))


def _write(mannequin, paths, measured, cushions):
    """Write every path (format from the extension); Blender is loaded only for .blend/.glb/.obj.

    A path that cannot be written raises UsageError naming it (not the temporary file behind it).
    """
    for path in paths:
        if core_format(path):
            with _writing(path):
                write_core_file(mannequin, path, cushions)
    blender = [p for p in paths if core_format(p) is None]
    if blender:
        _ensure_registered()
        from .services.files import write_mannequin

        try:
            write_mannequin(mannequin, blender, measured, cushions)
        except OSError as error:  # atomic_output names the file that failed
            if error.filename is None:
                raise
            raise _cannot_write(error.filename, error) from None
    return paths


@contextlib.contextmanager
def _writing(target, folder=False):
    """Turn an OSError while writing ``target`` (a file, or a folder with ``folder``) into one line naming it."""
    try:
        yield
    except OSError as error:
        raise _cannot_write(target, error, folder) from None


def _cannot_write(target, error, folder=False):
    where = os.path.abspath(target if folder else os.path.dirname(os.path.abspath(target)))
    blocker = _file_in_the_way(where)
    what = f"the folder {target}" if folder else target
    if not folder and os.path.isdir(target):
        reason = "it is a folder"
    elif blocker is not None:
        reason = "it is a file" if blocker == where and folder else f"{blocker} is a file, not a folder"
    else:
        reason = error.strerror or _one_line(error)
        if error.filename and os.path.abspath(error.filename) not in (os.path.abspath(target), where):
            reason += f" (creating a file in {where})"  # the temporary file it is written through
    return UsageError(f"cannot write {what}: {reason}")


def _file_in_the_way(folder):
    """The nearest existing path at or above ``folder`` if it is not a folder (nothing can be made under it)."""
    path = folder
    while not os.path.lexists(path):
        parent = os.path.dirname(path)
        if parent == path:
            return None
        path = parent
    return None if os.path.isdir(path) else path


def _output_folder(folder, command):
    """Make the output folder and check that files can be created in it, before any work is done; remove
    the temporaries a killed run of ElliMann left there (not those of one still running)."""
    with _writing(folder, folder=True):
        os.makedirs(folder, exist_ok=True)
        with tempfile.TemporaryFile(prefix=".ellimann-", dir=folder):
            pass
    removed = clean_stale_temporaries(folder)
    if removed:
        _say(f"{PROG} {command}: removed {len(removed)} temporary file(s) an interrupted run left in {folder}")


def _misses(measured, requested):
    """The requested measurements exact mode missed by more than its tolerance (EXACT_TOLERANCE, the
    criterion it stops at): [(key, m_T cm, requested cm, error %)]."""
    return [(key, float(m), float(r), abs(m - r) / r * 100.0) for key, m, r in zip(MEASUREMENTS, measured, requested)
            if abs(math.log(max(float(m), 1e-12) / float(r))) > EXACT_TOLERANCE]


def _missed_text(misses):
    return ("exact mode missed " + ", ".join(f"{key} by {error:.2f}% (m_T {m:.2f} cm for {r:g} cm)"
                                             for key, m, r, error in misses)
            + f" (tolerance {EXACT_TOLERANCE * 100:g}%; the file is the closest it found)")


# ------------------------------------------------------------------------------------------------ synth


def run_synth(args):
    kind = _output_kind(args.output)
    request = [getattr(args, key) for key in MEASUREMENTS]
    warnings = validate_request(request)
    reference = _references(args)
    result = synthesize_batch(reference, [request], args.mode, args.metric, args.power, normalize=args.normalize)
    mannequin, measured = result.mannequin(0, args.name), as_dict(result.measured[0])
    misses = _misses(result.measured[0], request) if args.mode == "exact" else []
    for warning in warnings + ([_missed_text(misses)] if misses else []):
        _say(f"{PROG} synth: warning: {warning}")
    _write(mannequin, [args.output], measured, args.cushions and kind != "json")
    error = relative_error(result.measured[0], request).max()
    _say(f"wrote {args.output}: '{mannequin.name}' ({args.mode}), m_T {_format_me(measured.values())} cm, "
         f"max error {error:.3f}%", file=sys.stdout)
    return MISSED if misses else 0


# ------------------------------------------------------------------------------------------------ batch


def parse_shard(text):
    if text is None:
        return 1, 1
    match = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", text)
    if not match or not 1 <= int(match.group(1)) <= int(match.group(2)):
        raise UsageError(f"--shard must be I/N with 1 <= I <= N, got {text!r}")
    return int(match.group(1)), int(match.group(2))


def parse_formats(text):
    formats = [f.strip().lower().lstrip(".") for f in text.split(",") if f.strip()]
    unknown = [f for f in formats if f not in FORMATS]
    if unknown or not formats:
        raise UsageError(f"--format takes a comma-separated list of {', '.join(FORMATS)}, got {text!r}")
    return list(dict.fromkeys(formats))


def read_rows(path):
    """Rows of a measurements CSV: list of (line, name, values or None, error or None)."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as stream:
            text = stream.read()
    except UnicodeDecodeError:
        raise UsageError(f"{path} is not a UTF-8 text CSV") from None
    reader = csv.reader(io.StringIO(text))
    header = next(reader, None)
    if not header:
        raise UsageError(f"{path} is empty; expected a header row He,Sh,Br,Wa,Hi[,name]")
    columns = {}
    for index, title in enumerate(header):
        key = title.strip()
        canonical = next((m for m in MEASUREMENTS + ("name",) if m.lower() == key.lower()), None)
        if canonical in columns:
            raise UsageError(f"{path}: column {canonical} appears twice in the header")
        if canonical:
            columns[canonical] = index
    missing = [m for m in MEASUREMENTS if m not in columns]
    if missing:
        raise UsageError(f"{path}: header lacks column(s) {', '.join(missing)}; expected He,Sh,Br,Wa,Hi[,name]")
    rows = []
    for line, record in enumerate(reader, start=2):
        if not any(cell.strip() for cell in record):
            continue
        name = record[columns["name"]].strip() if "name" in columns and columns["name"] < len(record) else ""
        try:
            values = []
            for key in MEASUREMENTS:
                cell = record[columns[key]].strip() if columns[key] < len(record) else ""
                if not cell:
                    raise MeasurementError(key, "is empty")
                try:
                    values.append(float(cell))
                except ValueError:
                    raise MeasurementError(key, f"{cell!r} is not a number (cm)") from None
            warnings = validate_request(values)
            if name and not NAME_PATTERN.match(name):
                raise MeasurementError("name", f"{name!r} must be letters, digits, '.', '_' or '-' (a file name)")
            rows.append((line, name, values, None, warnings))
        except MeasurementError as error:
            rows.append((line, name, None, str(error), []))
    return rows


def name_rows(rows):
    """Give every row its output name (``row-NNNNN`` from its line when the CSV has none) and refuse a row
    whose name an earlier row already uses (letter case ignored: the files would clash on macOS and
    Windows). Runs over the whole CSV before sharding, so every shard refuses the same rows."""
    seen, named = {}, []
    for line, name, values, error, warnings in rows:
        name = name or f"row-{line - 1:05d}"
        key = name.casefold()
        if error is None and key in seen:
            first_line, first_name = seen[key]
            same = "" if first_name == name else f" (as {first_name!r}; file names ignore case on some systems)"
            error = f"name: {name!r} is already used on line {first_line}{same}"
        if error is None:
            seen[key] = (line, name)
        named.append((line, name, values, error, warnings))
    return named


def run_batch(args):
    formats = parse_formats(args.format)
    shard, shards = parse_shard(args.shard)
    rows = read_rows(args.csv)
    if not rows:
        raise UsageError(f"{args.csv} has a header but no rows")
    reference = _references(args)
    rows = name_rows(rows)  # over the whole CSV, so every shard agrees on which rows are bad
    mine = [row for index, row in enumerate(rows) if index % shards == shard - 1]
    _output_folder(args.output, "batch")
    report_name = "report.csv" if shards == 1 else f"report-{shard}-of-{shards}.csv"
    report = _Report(os.path.join(args.output, report_name))
    jobs = []
    for line, name, values, error, warnings in mine:
        if error is not None:
            _say(f"{PROG} batch: line {line}: skipped: {error}")
            report.add(_report_row(line, name, "error", error, values))
            continue
        for warning in warnings:
            _say(f"{PROG} batch: line {line}: warning: {warning}")
        jobs.append((line, name, values, warnings))
    progress = _Progress(len(jobs), "batch")
    try:
        for start in range(0, len(jobs), CHUNK):
            chunk = jobs[start:start + CHUNK]
            result = synthesize_batch(reference, [values for _, _, values, _ in chunk], args.mode, args.metric,
                                      args.power, normalize=args.normalize)
            for i, (line, name, values, warnings) in enumerate(chunk):
                report.add(_batch_row(args, formats, result, i, line, name, values, warnings))
                progress.step(name)
    except KeyboardInterrupt:
        progress.done()
        report.finish()
        _say(f"{PROG} batch: interrupted: {report.count('ok', 'missed')} of {len(mine)} rows done, report "
             f"{report.path}; run it again with --resume to finish")
        return INTERRUPTED
    progress.done()
    report.finish()
    done, failed, missed = report.count("ok", "missed"), report.count("error"), report.count("missed")
    _say(f"{PROG} batch: {done} of {len(mine)} mannequins written to {args.output}"
         + (f" ({report.count('kept')} already complete, kept)" if args.resume else "")
         + (f" (shard {shard}/{shards} of {len(rows)} rows)" if shards > 1 else "") + f"; report {report.path}",
         file=sys.stdout)
    if failed:
        _say(f"{PROG} batch: error: {failed} row(s) failed; see {report.path}")
        return 1
    if missed:
        _say(f"{PROG} batch: warning: exact mode missed the request of {missed} row(s) by more than "
             f"{EXACT_TOLERANCE * 100:g}%; see {report.path}")
        return MISSED
    return 0


def _batch_row(args, formats, result, i, line, name, values, warnings):
    """Write (or, with --resume, keep) the files of one synthesized row; its report row. A failure is
    that row's: one line on stderr and status "error", and the batch goes on."""
    paths = [os.path.join(args.output, f"{name}.{_extension(kind)}") for kind in formats]
    notes = list(warnings)
    misses = _misses(result.measured[i], values) if args.mode == "exact" else []  # = not result.converged[i]
    if misses:
        notes.append(_missed_text(misses))
        _say(f"{PROG} batch: line {line}: warning: {_missed_text(misses)}")
    status = "missed" if misses else "ok"
    if args.resume and all(os.path.isfile(path) and incomplete(path) is None for path in paths):
        row = _report_row(line, name, status, "; ".join(notes + ["kept (--resume)"]), values, result.measured[i],
                          paths)
        row["kept"] = True
        return row
    try:
        _write(result.mannequin(i, name), paths, as_dict(result.measured[i]), args.cushions)
    except (ElliMannError, OSError, RuntimeError) as error:
        _say(f"{PROG} batch: line {line}: failed: {_one_line(error)}")
        return _report_row(line, name, "error", _one_line(error), values)
    return _report_row(line, name, status, "; ".join(notes), values, result.measured[i], paths)


REPORT_COLUMNS = (["line", "name", "status", "message"] + list(MEASUREMENTS)
                  + [f"{k}_measured" for k in MEASUREMENTS] + [f"{k}_error_pct" for k in MEASUREMENTS] + ["files"])


def _report_row(line, name, status, message, requested=None, measured=None, paths=()):
    """One report row; text from the CSV or messages is made safe for spreadsheets and terminals (:func:`_cell`)."""
    row = {"line": line, "name": _cell(name), "status": status, "message": _cell(message or ""),
           "files": _cell(" ".join(paths))}
    error = relative_error(measured, requested) if measured is not None else None
    for i, key in enumerate(MEASUREMENTS):
        row[key] = f"{requested[i]:g}" if requested is not None else ""
        row[f"{key}_measured"] = f"{measured[i]:.4f}" if measured is not None else ""
        row[f"{key}_error_pct"] = f"{error[i]:.4f}" if error is not None else ""
    return row


def _cell(text):
    """A report cell: control characters escaped (:func:`printable`), and text a spreadsheet would take for
    a formula (starting with =, +, - or @) neutralised with a leading apostrophe, as OWASP recommends."""
    text = printable(text)
    return "'" + text if text[:1] in ("=", "+", "-", "@") else text


def _report_csv(rows):
    stream = io.StringIO()
    writer = csv.DictWriter(stream, fieldnames=REPORT_COLUMNS, lineterminator="\n", extrasaction="ignore")
    writer.writeheader()
    writer.writerows(rows)
    return stream.getvalue()


class _Report:
    """A batch report, written as rows finish: each row is appended to REPORT.partial.csv and flushed, so a
    killed run leaves a record of what it did; :meth:`finish` writes REPORT.csv whole (sorted by line,
    atomically) and removes the partial file."""

    def __init__(self, path):
        self.path, self.rows = path, []
        root, extension = os.path.splitext(path)
        self.partial = f"{root}.partial{extension}"
        with _writing(self.partial):
            self.stream = open(self.partial, "w", newline="", encoding="utf-8")
        self.writer = csv.DictWriter(self.stream, fieldnames=REPORT_COLUMNS, lineterminator="\n",
                                     extrasaction="ignore")
        self._append(self.writer.writeheader)

    def add(self, row):
        self.rows.append(row)
        self._append(lambda: self.writer.writerow(row))

    def _append(self, write):
        if self.stream is None:
            return
        try:
            write()
            self.stream.flush()
        except OSError:  # the partial record is a courtesy; the report itself is written at the end
            self._close()

    def _close(self):
        if self.stream is not None:
            with contextlib.suppress(OSError):
                self.stream.close()
            self.stream = None

    def count(self, *statuses):
        if statuses == ("kept",):
            return sum(1 for row in self.rows if row.get("kept"))
        return sum(1 for row in self.rows if row["status"] in statuses)

    def finish(self):
        self._close()
        self.rows.sort(key=lambda row: row["line"])
        with _writing(self.path):
            atomic_write_text(self.path, _report_csv(self.rows))
        with contextlib.suppress(OSError):
            os.unlink(self.partial)


class _Progress:
    """One progress line on stderr: rewritten in place on a terminal, every ~5% in a log."""

    def __init__(self, total, command, every=None):
        self.total, self.count, self.start = total, 0, time.perf_counter()
        self.command = command
        self.stream = sys.stderr  # ElliMann's stderr, also from inside blender_output() (where sys.stderr is Blender's)
        self.tty = self.stream.isatty()
        self.every = every or max(1, total // 20)

    def step(self, name, count=None):
        """One more done (``name``: what), or ``count`` done so far; repeated counts are ignored."""
        if count is not None and count <= self.count:
            return
        self.count = self.count + 1 if count is None else count
        if self.tty or self.count % self.every == 0 or self.count == self.total:
            rate = self.count / max(time.perf_counter() - self.start, 1e-9)
            text = printable(f"{PROG} {self.command}: {self.count}/{self.total} ({rate:.1f}/s) {name}")
            print(f"\r{text[:100]:<100}" if self.tty else text, end="" if self.tty else "\n", file=self.stream,
                  flush=True)

    def done(self):
        if self.tty and self.total:
            print(file=self.stream)


# ------------------------------------------------------------------------------------------------ measure


def run_measure(args):
    path = args.file
    kind = os.path.splitext(path)[1].lower()
    if not os.path.isfile(path):
        raise UsageError(f"{path}: no such file")
    if kind == ".json":
        mannequin = _load_json_mannequin(path)
    elif kind == ".blend":
        mannequin = _load_blend_mannequin(path, args.collection)
    else:
        raise UsageError(f"FILE must be a .json or .blend mannequin, got {path!r}")
    values = mannequin.measure()
    if args.json:
        try:
            text = json.dumps({key: round(values[key], 4) for key in MEASUREMENTS}, allow_nan=False)
        except ValueError:  # NaN or infinity: not JSON, and not a measurement
            raise UsageError(f"{path}: m_T is not finite ({_format_me(values.values())} cm)") from None
        print(text)
    else:
        _say(f"{mannequin.name or path}: m_T", file=sys.stdout)
        for key in MEASUREMENTS:
            print(f"  {key} {MEASUREMENT_LABELS[key]:<17} {values[key]:9.2f} cm")
    return 0


def _load_json_mannequin(path):
    """Mannequin.load, its error naming the file."""
    try:
        return Mannequin.load(path)
    except MannequinError as error:
        text = _one_line(error)
        raise UsageError(text if path in text else f"{path}: {text}") from None


def _load_blend_mannequin(path, collection_name=None):
    bpy = _ensure_registered()
    from .bridge.convert import collection_to_mannequin, mannequin_collections
    try:
        with blender_output():
            bpy.ops.wm.open_mainfile(filepath=os.path.abspath(path), load_ui=False)
    except RuntimeError as error:
        raise UsageError(f"{path}: Blender cannot open it ({_one_line(error)})") from None
    candidates = [c for c in mannequin_collections() if c.ellimann.is_mannequin]
    if collection_name:
        candidates = [c for c in candidates if c.name == collection_name]
        if not candidates:
            raise UsageError(f"{path}: no mannequin collection named {collection_name!r}")
    if not candidates:
        raise UsageError(f"{path}: holds no ElliMann mannequin collection")
    if len(candidates) > 1:
        names = ", ".join(repr(c.name) for c in candidates)
        raise UsageError(f"{path}: holds several mannequins ({names}); choose one with --collection")
    return collection_to_mannequin(candidates[0])


# ------------------------------------------------------------------------------------------------ demo


def run_demo(args):
    reference = _references(args)
    out = args.output
    _output_folder(out, "demo")
    result = synthesize_batch(reference, [list(row) for row in TABLE_2_5], args.mode, args.metric, args.power,
                              normalize=args.normalize)
    rows, mannequins, missed = [], [], 0
    for i in range(len(result)):
        name = f"table_2_5_{i + 1:02d}"
        mannequin = result.mannequin(i)
        paths = [os.path.join(out, f"{name}.{kind}") for kind in ("blend", "json")]
        _write(mannequin, paths, as_dict(result.measured[i]), args.cushions)
        misses = _misses(result.measured[i], result.requests[i]) if args.mode == "exact" else []
        if misses:
            missed += 1
            _say(f"{PROG} demo: {name}: warning: {_missed_text(misses)}")
        rows.append(_report_row(i + 1, name, "missed" if misses else "ok",
                                "; ".join([mannequin.name] + ([_missed_text(misses)] if misses else [])),
                                result.requests[i], result.measured[i], paths))
        mannequins.append(mannequin)
        _say(f"{PROG} demo: wrote {name} ({mannequin.name})")
    for name, text in (("report.csv", _report_csv(rows)), ("report.md", _report_markdown(result, reference, args))):
        with _writing(os.path.join(out, name)):
            atomic_write_text(os.path.join(out, name), text)
    if args.picture:
        from .services.render import render_lineup

        with _writing(os.path.join(out, "lineup.png")):
            render_lineup(mannequins, os.path.join(out, "lineup.png"),
                          labels=[f"({i + 1})" for i in range(len(rows))], cushions=args.cushions)
    error = result.relative_error()
    _say(f"{PROG} demo: {len(rows)} mannequins in {out} ({args.mode}); m_T error mean {error.mean():.3f}%, "
         f"max {error.max():.3f}%; see {os.path.join(out, 'report.md')}", file=sys.stdout)
    return MISSED if missed else 0


def _report_markdown(result, reference, args):
    """Requested vs m_T per mannequin, and the error summary beside the paper's IDW."""
    paper = (args.mode, args.normalize, args.metric, args.power) == ("idw", PAPER_NORMALIZE, "raw", DEFAULT_POWER)
    idw = result if paper else synthesize_batch(reference, result.requests, "idw", "raw", DEFAULT_POWER,
                                                normalize=PAPER_NORMALIZE)
    error, idw_error = result.relative_error(), idw.relative_error()
    lines = [
        "# ElliMann demo: the ten mannequins of the paper's Table 2.5",
        "",
        f"Mode `{args.mode}`, IDW `{args.normalize}`, distance `{args.metric}`, p = {args.power:g}. Reference "
        "Mannequins: "
        f"{', '.join(reference.names)} ({len(reference.topology)} ellipsoids each).",
        "",
        "Requested measurements and m_T of the synthesized mannequin (cm); largest relative error (%) of this "
        "mode and of the paper's IDW (normalize `none`, distance `raw`, p = 2).",
        "",
        "| # | " + " | ".join(MEASUREMENTS) + " | " + " | ".join(f"m_T {k}" for k in MEASUREMENTS)
        + f" | max error % ({args.mode}) | max error % (paper IDW) |",
        "|---|" + "---:|" * (2 * len(MEASUREMENTS) + 2),
    ]
    for i in range(len(result)):
        cells = [f"{v:g}" for v in result.requests[i]] + [f"{v:.2f}" for v in result.measured[i]]
        cells += [f"{error[i].max():.3f}", f"{idw_error[i].max():.3f}"]
        lines.append(f"| {i + 1} | " + " | ".join(cells) + " |")
    lines += ["", "Relative error (%) over the ten:", "", "| | " + " | ".join(MEASUREMENTS) + " |",
              "|---|" + "---:|" * len(MEASUREMENTS)]
    for label, values in ((f"mean, {args.mode}", error.mean(axis=0)), (f"max, {args.mode}", error.max(axis=0)),
                          ("mean, paper IDW", idw_error.mean(axis=0)), ("max, paper IDW", idw_error.max(axis=0))):
        if paper and label.endswith("IDW"):
            continue
        lines.append(f"| {label} | " + " | ".join(f"{v:.3f}" for v in values) + " |")
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------------------------------------ drape


def run_drape(args):
    for path, ending, what in ((args.output, ".blend", "-o"), (args.render, ".png", "--render")):
        if path is not None and not path.lower().endswith(ending):
            raise UsageError(f"{what} must end in {ending}, got {path!r}")
    kind = os.path.splitext(args.mannequin)[1].lower()
    if kind not in (".json", ".blend"):
        raise UsageError(f"MANNEQUIN must be a .json or .blend mannequin, got {args.mannequin!r}")
    if kind == ".json" and args.collection is not None:
        raise UsageError(f"--collection picks one of the mannequins in a .blend; {args.mannequin} is a .json file "
                         "holding one mannequin (leave --collection out)")
    if not os.path.isfile(args.mannequin):
        raise UsageError(f"{args.mannequin}: no such file")
    if kind == ".json":
        mannequin = _load_json_mannequin(args.mannequin)
    bpy = _ensure_registered()
    from .services.drape import WARN_CLOTH_VERTICES, check_cloth_size, drape
    from .services.files import atomic_output
    from .services.scene import add_mannequin, empty_scene

    settings = drape_settings(args)
    if kind == ".json":
        empty_scene()
        add_mannequin(mannequin, cushions=settings.cushions and bool(mannequin.topology.cushion_pairs))
    else:
        mannequin = _load_blend_mannequin(args.mannequin, args.collection)
    vertices, size = check_cloth_size(mannequin, args.garment, settings)  # refuses a cloth too large to drape
    if vertices > WARN_CLOTH_VERTICES:
        _say(f"{PROG} drape: warning: the cloth will have about {vertices:,} vertices and need about "
             f"{size / 1e9:.1f} GB; it is slow (a larger --edge is faster)")
    _say(f"{PROG} drape: {args.garment} on '{mannequin.name}', {settings.frames} frames, cloth edge "
         f"{settings.edge * CM_PER_M:g} cm, colliding with {'cushions' if settings.cushions else 'ellipsoids'}")
    progress = _Progress(settings.frames, "drape", every=max(10, settings.frames // 20))  # 10 frames, 5% past 200

    def frame_done(frame):
        progress.step("frames simulated" + ("; baking and measuring the fit" if frame == settings.frames else ""),
                      frame)

    with blender_output():
        try:
            result = drape(mannequin, args.garment, settings, progress=frame_done)
        finally:
            progress.done()
        with _writing(args.output), atomic_output(args.output) as temp:
            bpy.ops.wm.save_as_mainfile(filepath=temp, copy=True, check_existing=False)
    _say(f"wrote {args.output}: {result.garment.name} on '{mannequin.name}', {result.summary()}", file=sys.stdout)
    if args.render:
        from .services.render import render_view

        low, high = bounds(mannequin.rotation, mannequin.center, mannequin.semi_axes)
        with _writing(args.render):
            render_view(args.render, low.min(axis=0), high.max(axis=0))
        _say(f"wrote {args.render}", file=sys.stdout)
    return 0


def drape_settings(args):
    """DrapeSettings from the command line: what is not given keeps DrapeSettings' default (the panel's too)."""
    from .drape import DrapeSettings

    low, high = (bound * CM_PER_M for bound in EDGE_RANGE)
    if args.edge is not None and not low <= args.edge <= high:  # in the flag's unit, not DrapeSettings' metres
        raise UsageError(f"--edge: the cloth's edge length must be from {low:g} to {high:g} cm, got {args.edge:g} cm")
    given = {"frames": args.frames, "edge": None if args.edge is None else args.edge / CM_PER_M,
             "cushions": args.cushions}
    return dataclasses.replace(DrapeSettings(), **{k: v for k, v in given.items() if v is not None}).checked()


# ------------------------------------------------------------------------------------------------ Blender


_handle = None


def register():
    """Make ``blender --command ellimann …`` run :func:`main`."""
    global _handle
    import bpy

    _handle = bpy.utils.register_cli_command(PROG, main)


def unregister():
    global _handle
    import bpy

    if _handle is not None:
        bpy.utils.unregister_cli_command(_handle)
        _handle = None
