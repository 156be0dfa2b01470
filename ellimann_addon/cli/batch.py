"""``ellimann batch``: one mannequin per row of a measurements CSV, the files in every --format, and a report
(requested vs measured) written row by row; --shard for a render farm, --resume after an interruption."""

import contextlib
import csv
import io
import os
import re
import sys

import numpy as np

from ..core.constants import MEASUREMENTS
from ..core.errors import ElliMannError, MeasurementError, ReferenceSetError
from ..core.files import atomic_write_text, incomplete
from ..core.formats.table import FORMATS
from ..core.mannequin.skeleton import JOINT_NAMES
from ..core.measure.extra import EXTRA_MEASUREMENTS
from ..core.measure.tailor import as_dict
from ..core.synthesis.batch import CHUNK, synthesize_chunk
from ..core.synthesis.extra_refine import extra_request_problems, meet_extra
from ..core.synthesis.refine import EXACT_TOLERANCE
from ..core.synthesis.request import validate_request
from . import arguments, distributed, output, reporting, writing
from .output import PROG, UsageError

NAME_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,99}$")
MAX_WARNING_LINES = 20  # range warnings printed before the rest go to the report only (a population has thousands)
NPZ = "npz"  # the batch's one-file format (core.formats.npz_bundle), written once at the end


def add_parser(commands):
    batch = commands.add_parser(
        "batch",
        help="synthesize every row of a CSV",
        description="One mannequin per CSV row. The header names the columns "
        "He,Sh,Br,Wa,Hi (cm) and optionally name and references (a row's "
        "reference set: female, male or a folder; empty: --references) "
        "and any of the extra measurements (neck, upper_arm, thigh, calf, "
        "crotch_height, arm_length: the keys measure --json prints; an empty "
        "cell leaves it to the reference set). Writes the files and "
        "DIR/report.csv (requested vs measured), row by row into "
        "DIR/report.partial.csv while it runs. Bad or failed rows are "
        "reported and skipped; the exit code is 1 if any row failed, 3 if "
        "exact mode missed a row's request, 130 if interrupted.",
    )
    batch.add_argument("csv", metavar="MEASUREMENTS.csv")
    batch.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")
    batch.add_argument(
        "--format",
        default="json",
        help=f"comma-separated output formats among {','.join(FORMATS)},npz (default json; mjcf "
        "writes NAME.xml; npz writes every mannequin of the batch into one compressed file "
        "DIR/mannequins.npz, docs/batch_file.md)",
    )
    batch.add_argument(
        "--dask",
        metavar="ADDRESS",
        help="synthesize on a Dask cluster: a scheduler's tcp://HOST:PORT, or local:N for N local "
        "worker processes (pip install ellimann[dask]); results identical to a serial run",
    )
    batch.add_argument(
        "--shard",
        metavar="I/N",
        help="process only rows I, I+N, I+2N… (I from 1 to N), for a render farm; the report is DIR/report-I-of-N.csv",
    )
    batch.add_argument(
        "--resume",
        action="store_true",
        help="skip rows whose files (every --format) are already in DIR and whole, e.g. after an "
        "interrupted run with the same CSV and options; without it every row is written again",
    )
    arguments.add_synthesis_options(batch)
    arguments.add_pose_option(batch)
    batch.set_defaults(run=run, blender=needs_blender)


def needs_blender(args):
    """What needs Blender in this command (None: nothing)."""
    try:
        formats = parse_formats(args.format)
    except UsageError:
        return None
    blender = [f for f in formats if f in FORMATS and FORMATS[f].needs_blender_for(args.pose is not None)]
    return f"--format {blender[0]}" if blender else None


def parse_shard(text):
    if text is None:
        return 1, 1
    match = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", text)
    if not match or not 1 <= int(match.group(1)) <= int(match.group(2)):
        raise UsageError(f"--shard must be I/N with 1 <= I <= N, got {text!r}")
    return int(match.group(1)), int(match.group(2))


def parse_formats(text):
    formats = [f.strip().lower().lstrip(".") for f in text.split(",") if f.strip()]
    unknown = [f for f in formats if f not in FORMATS and f != NPZ]
    if unknown or not formats:
        raise UsageError(f"--format takes a comma-separated list of {', '.join(FORMATS)}, {NPZ}, got {text!r}")
    return list(dict.fromkeys(formats))


def read_rows(path, reference_of):
    """Rows of a measurements CSV: list of (line, name, values or None, error or None, warnings, reference).

    ``reference_of(text)``: the ReferenceSet of a ``references`` cell ("" for the command's own), whose
    ranges and limits the row is checked against; a cell naming no usable set is that row's error."""
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
        canonical = next(
            (m for m in MEASUREMENTS + EXTRA_MEASUREMENTS + ("name", "references") if m.lower() == key.lower()), None
        )
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
        name, chosen = (
            record[columns[c]].strip() if c in columns and columns[c] < len(record) else ""
            for c in ("name", "references")
        )
        reference = None
        try:
            try:
                reference = reference_of(chosen)
            except ReferenceSetError as error:
                raise MeasurementError("references", output.one_line(error)) from None
            values = []
            for key in MEASUREMENTS:
                cell = record[columns[key]].strip() if columns[key] < len(record) else ""
                if not cell:
                    raise MeasurementError(key, "is empty")
                try:
                    values.append(float(cell))
                except ValueError:
                    raise MeasurementError(key, f"{cell!r} is not a number (cm)") from None
            warnings = validate_request(values, reference.ranges, reference.absurd_limits)
            extra = _extra_cells(record, columns)
            problems = extra_request_problems(dict(zip(MEASUREMENTS, values)), extra)
            if problems:
                raise MeasurementError(problems[0].split(" ")[0], problems[0].split(" ", 1)[1])
            if name and not NAME_PATTERN.match(name):
                raise MeasurementError("name", f"{name!r} must be letters, digits, '.', '_' or '-' (a file name)")
            rows.append((line, name, values, None, warnings, reference, extra))
        except MeasurementError as error:
            rows.append((line, name, None, str(error), [], reference, {}))
    return rows


def _extra_cells(record, columns):
    """The extra measurements a row gives (an empty cell: not given, the reference set's)."""
    extra = {}
    for key in EXTRA_MEASUREMENTS:
        cell = record[columns[key]].strip() if key in columns and columns[key] < len(record) else ""
        if cell:
            try:
                extra[key] = float(cell)
            except ValueError:
                raise MeasurementError(key, f"{cell!r} is not a number (cm)") from None
    return extra


def name_rows(rows):
    """Give every row its output name (``row-NNNNN`` from its line when the CSV has none) and refuse a row
    whose name an earlier row already uses (letter case ignored: the files would clash on macOS and
    Windows). Runs over the whole CSV before sharding, so every shard refuses the same rows."""
    seen, named = {}, []
    for line, name, values, error, warnings, reference, extra in rows:
        name = name or f"row-{line - 1:05d}"
        key = name.casefold()
        if error is None and key in seen:
            first_line, first_name = seen[key]
            same = "" if first_name == name else f" (as {first_name!r}; file names ignore case on some systems)"
            error = f"name: {name!r} is already used on line {first_line}{same}"
        if error is None:
            seen[key] = (line, name)
        named.append((line, name, values, error, warnings, reference, extra))
    return named


def run(args):
    formats = parse_formats(args.format)
    pose_file = arguments.check_pose_argument(args, formats)
    shard, shards = parse_shard(args.shard)
    sets = {"": arguments.references(args)}  # the command's set, read once, and each other set a row names

    def reference_of(chosen):
        if chosen not in sets:
            sets[chosen] = arguments.references(args, chosen)
        return sets[chosen]

    rows = read_rows(args.csv, reference_of)
    if not rows:
        raise UsageError(f"{args.csv} has a header but no rows")
    options = arguments.synthesis_options(args)
    rows = name_rows(rows)  # over the whole CSV, so every shard agrees on which rows are bad
    mine = [row for index, row in enumerate(rows) if index % shards == shard - 1]
    cluster = distributed.connect(args.dask) if args.dask else None  # before anything is written
    try:
        return _run(args, formats, shard, shards, rows, mine, options, cluster, pose_file)
    finally:
        if cluster is not None:
            cluster.close()


def _run(args, formats, shard, shards, rows, mine, options, cluster, pose_file):
    writing.output_folder(args.output, "batch")
    suffix = "" if shards == 1 else f"-{shard}-of-{shards}"
    report = Report(os.path.join(args.output, f"report{suffix}.csv"))
    jobs, shown = [], 0
    for line, name, values, error, warnings, reference, extra in mine:
        if error is not None:
            output.say(f"{PROG} batch: line {line}: skipped: {error}")
            report.add(reporting.report_row(line, name, "error", error, values))
            continue
        for warning in warnings:
            shown += 1
            if shown <= MAX_WARNING_LINES:
                output.say(f"{PROG} batch: line {line}: warning: {warning}")
        jobs.append((line, name, values, warnings, extra, reference))
    if shown > MAX_WARNING_LINES:
        output.say(
            f"{PROG} batch: {shown - MAX_WARNING_LINES} more warning(s) of requests outside the reference "
            f"range; every row's are in {report.path}"
        )
    progress = output.Progress(len(jobs), "batch", quiet=args.quiet)
    # one core batch per reference set (in the order the sets first appear), in chunks
    groups = {}
    for job in jobs:
        groups.setdefault(id(job[-1]), []).append(job)
    chunks = [group[start : start + CHUNK] for group in groups.values() for start in range(0, len(group), CHUNK)]
    sets = [chunk[0][-1] for chunk in chunks]
    requests = [[job[2] for job in chunk] for chunk in chunks]
    bundles = {}  # one batch file per reference set: mannequins.npz, or mannequins-NAME.npz when a batch uses several
    if NPZ in formats:
        for reference in dict.fromkeys(sets):
            tag = f"-{reference.name}" if len(groups) > 1 else ""
            bundles[id(reference)] = Bundle(
                os.path.join(args.output, f"mannequins{tag}{suffix}.npz"), reference.topology, args.mode
            )
    results = (
        cluster.map(sets, requests, options)
        if cluster is not None
        else ((index, synthesize_chunk(sets[index], chunk, options)) for index, chunk in enumerate(requests))
    )
    try:
        for index, result in results:
            for i, (line, name, values, warnings, extra, reference) in enumerate(chunks[index]):
                report.add(
                    _row(
                        args,
                        formats,
                        result,
                        i,
                        line,
                        name,
                        values,
                        warnings,
                        reference.name,
                        bundles.get(id(reference)),
                        index,
                        pose_file,
                        extra,
                    )
                )
                progress.step(name)
        for bundle in bundles.values():
            bundle.write()
    except KeyboardInterrupt:
        progress.done()
        report.finish()
        output.say(
            f"{PROG} batch: interrupted: {report.count('ok', 'missed')} of {len(mine)} rows done, report "
            f"{report.path}; run it again with --resume to finish"
        )
        return output.INTERRUPTED
    except BaseException:
        report._close()  # the partial report stays for --resume; its file is not left open
        raise
    progress.done()
    report.finish()
    done, failed, missed = report.count("ok", "missed"), report.count("error"), report.count("missed")
    output.say(
        f"{PROG} batch: {done} of {len(mine)} mannequins written to {args.output}"
        + (f" ({report.count('kept')} already complete, kept)" if args.resume else "")
        + (f" (shard {shard}/{shards} of {len(rows)} rows)" if shards > 1 else "")
        + f"; report {report.path}",
        file=sys.stdout,
    )
    if failed:
        output.say(f"{PROG} batch: error: {failed} row(s) failed; see {report.path}")
        return 1
    if missed:
        output.say(
            f"{PROG} batch: warning: exact mode missed the request of {missed} row(s) by more than "
            f"{EXACT_TOLERANCE * 100:g}%; see {report.path}"
        )
        return output.MISSED
    return 0


def _row(
    args, formats, result, i, line, name, values, warnings, references, bundle=None, chunk=0, pose_file=None, extra=None
):
    """Write (or, with --resume, keep) the files of one synthesized row, and add it to the batch file; its report
    row. A failure is that row's: one line on stderr and status "error", and the batch goes on. A row with extra
    measurements is deformed to meet them too (exact mode; the report's message gives what they came to; the
    batch file holds the five's mannequin)."""
    if result.errors[i] is not None:
        output.say(f"{PROG} batch: line {line}: failed: {result.errors[i]}")
        return reporting.report_row(line, name, "error", result.errors[i], values)
    paths = [os.path.join(args.output, f"{name}.{writing.extension(kind)}") for kind in formats if kind != NPZ]
    notes = list(warnings)
    mannequin, measured = result.mannequin(i, name, values), result.measured[i]
    if extra and args.mode == "exact":
        mannequin, achieved, missed_extra = meet_extra(mannequin, extra)
        measured = np.array([achieved[key] for key in MEASUREMENTS])
        notes.append("extra: " + ", ".join(f"{key} {achieved[key]:.2f}" for key in extra))
        notes += [f"exact mode missed {text}" for text in missed_extra]
    elif extra:
        notes.append("the extra measurements are met in exact mode only (IDW gives the reference set's)")
    misses = reporting.misses(measured, values) if args.mode == "exact" else []  # = not result.converged[i]
    if misses:
        notes.append(reporting.missed_text(misses))
        output.say(f"{PROG} batch: line {line}: warning: {reporting.missed_text(misses)}")
    status = "missed" if misses else "ok"
    listed = paths + ([bundle.path] if bundle is not None else [])
    if bundle is not None:
        bundle.add(chunk, name, values, result, i)
    if args.resume and all(os.path.isfile(path) and incomplete(path) is None for path in paths) and paths:
        row = reporting.report_row(
            line, name, status, "; ".join(notes + ["kept (--resume)"]), values, measured, listed, references
        )
        row["kept"] = True
        return row
    try:
        if paths:
            frames = arguments.pose_frames(args, mannequin, pose_file, notes)
            writing.write(mannequin, paths, as_dict(measured), args.cushions, frames, args.fps)
    except (ElliMannError, OSError, RuntimeError) as error:
        output.say(f"{PROG} batch: line {line}: failed: {output.one_line(error)}")
        if bundle is not None:
            bundle.drop(chunk, name)
        return reporting.report_row(line, name, "error", output.one_line(error), values)
    return reporting.report_row(line, name, status, "; ".join(notes), values, measured, listed, references)


class Bundle:
    """The rows of ``--format npz``, gathered by chunk (a Dask run finishes chunks in any order) and written
    once, in the CSV's order, when the batch ends (``core.formats.npz_bundle``)."""

    def __init__(self, path, topology, mode):
        self.path, self.topology, self.mode = path, topology, mode
        self.rows = {}  # chunk -> [(name, request, result, i)]

    def add(self, chunk, name, values, result, i):
        self.rows.setdefault(chunk, []).append((name, values, result, i))

    def drop(self, chunk, name):
        self.rows[chunk] = [row for row in self.rows.get(chunk, []) if row[0] != name]

    def write(self):
        from ..core.formats.npz_bundle import batch_arrays, write_batch_file

        rows = [row for chunk in sorted(self.rows) for row in self.rows[chunk]]
        parts = len(self.topology)
        shapes = {
            "rotation": (parts, 3, 3),
            "center": (parts, 3),
            "semi_axes": (parts, 3),
            "measured": (5,),
            "factors": (5,),
            "converged": (),
        }
        arrays = {
            key: np.array([getattr(result, key)[i] for _, _, result, i in rows]).reshape((len(rows),) + shape)
            for key, shape in shapes.items()
        }
        requests = np.array([values for _, values, _, _ in rows], dtype=float).reshape(len(rows), 5)
        joints = None
        if rows and all(result.joints is not None for _, _, result, _ in rows):
            joints = np.array([result.joints[i] for _, _, result, i in rows]).reshape(len(rows), len(JOINT_NAMES), 3)
        with writing.writing(self.path):
            write_batch_file(
                self.path,
                batch_arrays(
                    self.topology,
                    [row[0] for row in rows],
                    requests,
                    mode=self.mode,
                    joints=joints,
                    joint_names=JOINT_NAMES,
                    **arrays,
                ),
            )


class Report:
    """A batch report, written as rows finish: each row is appended to REPORT.partial.csv and flushed, so a
    killed run leaves a record of what it did; :meth:`finish` writes REPORT.csv whole (sorted by line,
    atomically) and removes the partial file."""

    def __init__(self, path):
        self.path, self.rows = path, []
        root, extension = os.path.splitext(path)
        self.partial = f"{root}.partial{extension}"
        with writing.writing(self.partial):
            self.stream = open(self.partial, "w", newline="", encoding="utf-8")
        self.writer = csv.DictWriter(
            self.stream, fieldnames=reporting.REPORT_COLUMNS, lineterminator="\n", extrasaction="ignore"
        )
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
        with writing.writing(self.path):
            atomic_write_text(self.path, reporting.report_csv(self.rows))
        with contextlib.suppress(OSError):
            os.unlink(self.partial)
