"""``ellimann batch``: one mannequin per row of a measurements CSV, the files in every --format, and a report
(requested vs measured) written row by row; --shard for a render farm, --resume after an interruption.

A batch streams: the CSV is read a chunk of rows at a time (``batch_csv``), each chunk synthesized by the core
(``core.synthesis.batch``; on Dask a bounded window of chunks in flight) and its results taken in the CSV's order
into the files, the report and the .npz (``core.formats.npz_bundle.BatchFileWriter``), so memory stays flat in
the row count."""

import collections
import os
import re
import sys

import numpy as np

from ..core.errors import ElliMannError
from ..core.files import incomplete
from ..core.formats.npz_bundle import BatchFileWriter
from ..core.formats.table import BATCH_FILE, format_named, listing
from ..core.job.result import tolerance_text
from ..core.mannequin.skeleton import JOINT_NAMES
from ..core.measure.tailor import as_dict
from ..core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ..core.synthesis.batch import by_reference_set, chunks, synthesize_chunk
from ..core.synthesis.misses import missed_text
from . import arguments, distributed, jobs, output, reporting, skin_options, writing
from .batch_csv import MeasurementsCsv
from .output import PROG, UsageError
from .provenance import SAID, Provenance

NAME_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,99}$")
MAX_WARNING_LINES = 20  # range warnings printed before the rest go to the report only (a population has thousands)
NPZ = BATCH_FILE.name  # the batch's one-file format (core.formats.npz_bundle), streamed as rows come


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
        "DIR/report.partial.csv while it runs. A column it does not read is "
        "named before any row is made (a misspelt one is refused). Bad or failed rows are "
        "reported and skipped; the exit code is 1 if any row failed, 3 if "
        "exact mode missed a row's request, 130 if interrupted.",
    )
    batch.add_argument("csv", metavar="MEASUREMENTS.csv")
    batch.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")
    batch.add_argument(
        "--format",
        default="json",
        help=f"comma-separated output formats among {listing(what='name')}, {NPZ} (default json; mjcf writes "
        f"NAME.xml, as synth's .xml; {NPZ} writes every mannequin of the batch into one compressed file "
        "DIR/mannequins.npz, docs/formats/batch_npz.md)",
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
        help="keep the rows whose files (every --format) are already in DIR, whole, and were made from the same "
        "row and settings (DIR/made_from/NAME.json records what each row was made from), e.g. after an interrupted "
        "run; a row whose request, reference set or options changed is made again and the report says why; without "
        "it every row is written again",
    )
    arguments.add_synthesis_options(batch)
    arguments.add_pose_option(batch)
    skin_options.add_skin_options(batch)
    batch.set_defaults(run=run, blender=lambda args: None)  # the batch's job checks its files


def parse_shard(text):
    if text is None:
        return 1, 1
    match = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", text)
    if not match or not 1 <= int(match.group(1)) <= int(match.group(2)):
        raise UsageError(f"--shard must be I/N with 1 <= I <= N, got {text!r}")
    return int(match.group(1)), int(match.group(2))


def parse_formats(text):
    """The formats of ``--format`` (rows of ``core.formats.table``: their names, or an extension, xml for MJCF as
    ``synth -o NAME.xml``), and whether the batch file (npz) is asked."""
    words = [word.strip() for word in text.split(",") if word.strip()]
    found = [format_named(word, batch=True) for word in words]
    if not words or None in found:
        raise UsageError(f"--format takes a comma-separated list of {listing(what='name')}, {NPZ}, got {text!r}")
    kinds = list(dict.fromkeys(found))
    return [kind for kind in kinds if kind is not BATCH_FILE], BATCH_FILE in kinds


def run(args):
    from ..core.job.request import Request

    formats, bundled = parse_formats(args.format)
    shard, shards = parse_shard(args.shard)
    options = arguments.synthesis_options(args)
    skin = skin_options.skin_settings(args)
    sets = {"": arguments.references(args)}  # the command's set, read once, and each other set a row names

    def reference_of(chosen):
        if chosen not in sets:
            sets[chosen] = arguments.references(args, chosen)
        return sets[chosen]

    if skin is not None and bundled:
        raise UsageError("--skin with --format npz: the batch file holds the pieces only; write json, obj or mjcf")
    if skin is not None and args.dask:
        raise UsageError("--skin with --dask: skins are made one row at a time in this process; drop --dask")
    # the whole command checked once, on the command's set, before anything is written: every row's job is that
    # one with its own measurements, set and names (rows of another set are checked as they come)
    reference = sets[""]
    command = jobs.checked(
        Request(
            dict(zip(MEASUREMENTS, reference.measurements[0])),
            reference,
            options=options,
            cushions=args.cushions,
            skin=skin,
            pose=arguments.pose_ask(args),
            outputs=tuple(os.path.join(args.output, f"NAME.{kind.extension}") for kind in formats),
        ),
        blender_use=lambda kind: f"--format {kind.name}",
    )
    table = MeasurementsCsv(args.csv, shard, shards)  # the header checked and the rows counted
    if not table.count:
        raise UsageError(f"{args.csv} has a header but no rows")
    for warning in table.warnings():  # what of the file is not read, before any row is made
        output.say(f"{PROG} {args.command}: warning: {warning}")
    arguments.say_clip(args, command.pose)
    cluster = distributed.connect(args.dask) if args.dask else None  # before anything is written
    try:
        return _run(args, command, formats, bundled, shard, shards, table, reference_of, cluster)
    finally:
        if cluster is not None:
            cluster.close()


def _run(args, command, formats, bundled, shard, shards, table, reference_of, cluster):
    writing.output_folder(args.output, "batch")
    suffix = "" if shards == 1 else f"-{shard}-of-{shards}"
    report = reporting.Report(os.path.join(args.output, f"report{suffix}.csv"))
    mine = len(range(shard - 1, table.count, shards))
    progress = output.Progress(mine, "batch", quiet=args.quiet)
    # one batch file per reference set: mannequins.npz, or mannequins-NAME.npz when the rows name several
    made = Provenance(args.output, command)  # what each row's files are made from (--resume compares it)
    bundles = Bundles(args.output, suffix, args.mode, len(table.references) > 1, made) if bundled else None
    rows = (row for index, row in enumerate(table.rows(reference_of, NAME_PATTERN)) if index % shards == shard - 1)
    reading, window = chunks(rows), collections.deque()  # chunks read and sent, in the CSV's order
    announced = Announcer(report.path)
    try:
        while True:
            while len(window) < (cluster.window if cluster is not None else 1):
                chunk = next(reading, None)
                if chunk is None:
                    break
                announced.rows(chunk)
                window.append(Chunk(chunk, command.options, cluster))
            if not window:
                break
            chunk = window[0]
            for row, (result, i) in chunk.outcomes():
                report.add(_row(args, command, formats, result, i, row, bundles, made))
                chunk.done += 1
                progress.step(row.name)
            window.popleft()
            if bundles is not None:
                bundles.add(chunk)
        if bundles is not None:
            bundles.finish()
    except KeyboardInterrupt:
        progress.done()
        for chunk in window:  # the refused rows read so far, after those done (the CSV's order holds)
            for row in chunk.rows[chunk.done :]:
                if row.error is not None:
                    report.add(reporting.report_row(row.line, row.name, "error", row.error, row.values))
        report.finish()
        if bundles is not None:
            bundles.discard()
        output.say(
            f"{PROG} batch: interrupted: {report.count('ok', 'missed')} of {mine} rows done, report "
            f"{report.path}; run it again with --resume to finish"
        )
        return output.INTERRUPTED
    except BaseException:
        report.close()  # the partial report stays for --resume
        if bundles is not None:
            bundles.discard()
        raise
    progress.done()
    announced.done()
    report.finish()
    done, failed, missed = report.count("ok", "missed"), report.count("error"), report.count("missed")
    redone = f"; {report.count('redone')} made again: their row or settings changed" if report.count("redone") else ""
    output.say(
        f"{PROG} batch: {done} of {mine} mannequins written to {args.output}"
        + (f" ({report.count('kept')} already complete, kept{redone})" if args.resume else "")
        + (f" (shard {shard}/{shards} of {table.count} rows)" if shards > 1 else "")
        + f"; report {report.path}",
        file=sys.stdout,
    )
    if failed:
        output.say(f"{PROG} batch: error: {failed} row(s) failed; see {report.path}")
        return 1
    if missed:
        tolerance = tolerance_text(command.skin is not None)
        output.say(
            f"{PROG} batch: warning: exact mode missed the request of {missed} row(s) by more than {tolerance}; "
            f"see {report.path}"
        )
        return output.MISSED
    return 0


class Announcer:
    """The lines a chunk's rows get when they are read: a refused row's, and the first MAX_WARNING_LINES warnings
    of requests outside the reference range (a population has thousands; the rest are in the report)."""

    def __init__(self, report):
        self.report, self.warnings = report, 0

    def rows(self, rows):
        for row in rows:
            if row.error is not None:
                output.say(f"{PROG} batch: line {row.line}: skipped: {row.error}")
                continue
            for warning in row.warnings:
                self.warnings += 1
                if self.warnings <= MAX_WARNING_LINES:
                    output.say(f"{PROG} batch: line {row.line}: warning: {warning}")

    def done(self):
        if self.warnings > MAX_WARNING_LINES:
            output.say(
                f"{PROG} batch: {self.warnings - MAX_WARNING_LINES} more warning(s) of requests outside the "
                f"reference range; every row's are in {self.report}"
            )


class Chunk:
    """Consecutive rows of the CSV and their synthesis: on the cluster, sent when read; serially, run when its
    results are taken. ``done``: how many of its rows are reported."""

    def __init__(self, rows, options, cluster):
        self.rows, self.options, self.cluster, self.done = rows, options, cluster, 0
        good = [position for position, row in enumerate(rows) if row.error is None]
        self.groups = [
            (reference, [good[k] for k in members])
            for reference, members in by_reference_set([rows[position].reference for position in good])
        ]
        self.work = [
            (reference, np.array([rows[p].values for p in members], dtype=float), [rows[p].extra for p in members])
            for reference, members in self.groups
        ]
        self.submitted = cluster.submit(self.work, options) if cluster is not None else None

    def outcomes(self):
        """(row, (SynthesizedBatch, index) or (None, None) for a refused row), in the rows' order."""
        if self.cluster is not None:
            results = self.cluster.results(self.submitted)
        else:
            results = [
                synthesize_chunk(reference, requests, self.options, extras) for reference, requests, extras in self.work
            ]
        where = [(None, None)] * len(self.rows)
        for (_, members), result in zip(self.groups, results):
            for i, position in enumerate(members):
                where[position] = (result, i)
        return list(zip(self.rows, where))


def _row(args, command, formats, result, i, row, bundles=None, made=None):
    """Write (or, with --resume, keep) the files of one row, and mark it for the batch file; its report row. A
    refused row (``result`` None) or a failure is that row's: one line on stderr and status "error", and the batch
    goes on. The row's job is the ``command``'s with its own request (``core.job.request.row_job``), finished from
    its synthesized mannequin (``core.job.make.finish``: its skin, poses and misses); a row that asks for extra
    measurements has them met (exact mode, ``core.synthesis.batch``), and the report gives what each measurement
    asked came to. ``made``: the batch's Provenance: --resume keeps a row's files only when they are all there,
    whole, and were made from this row and these settings; otherwise they are made again, and the report says why
    ("redone (--resume: He changed)")."""
    from ..core.job.make import finish, synthesized_misses
    from ..core.job.request import row_job

    line, name, values, extra = row.line, row.name, row.values, row.extra
    if result is None:
        return reporting.report_row(line, name, "error", row.error, values)
    if result.error(i) is not None:
        output.say(f"{PROG} batch: line {line}: failed: {result.error(i)}")
        return reporting.report_row(line, name, "error", result.error(i), values, extra=extra)
    paths = [os.path.join(args.output, f"{name}.{kind.extension}") for kind in formats]
    job = row_job(command, dict(zip(MEASUREMENTS, values)), row.reference, extra, row.warnings, name, paths)
    mannequin = result.mannequin(i, name)
    measured = as_dict(result.measured[i])
    if extra:
        measured.update(
            (key, float(value)) for key, value in zip(EXTRA_MEASUREMENTS, result.extra_measured[i]) if key in extra
        )
    bundle = bundles.path_of(row.reference) if bundles is not None else None
    listed = paths + ([bundle] if bundle is not None else [])
    whole = bool(paths) and args.resume and all(os.path.isfile(path) and incomplete(path) is None for path in paths)
    changed = made.changed(row) if whole and made is not None else None
    kept = whole and changed is None
    notes = [f"redone (--resume: {changed})"] if changed else []
    if changed:
        made.redone += 1
        if made.redone <= SAID:
            output.say(
                f"{PROG} batch: line {line}: {name}'s files were made from another row or settings ({changed}): "
                "made again"
            )
    made_now = None
    if not kept:
        try:
            if paths and made is not None:
                made.forget(name)  # no record while its files are being written again
            made_now = finish(job, mannequin, measured)
            if paths:
                writing.write(made_now, job.formats, args.cushions, job.avatar)
            if paths and made is not None:
                made.write(row)
        except (ElliMannError, OSError, RuntimeError) as error:
            output.say(f"{PROG} batch: line {line}: failed: {output.one_line(error)}")
            return reporting.report_row(line, name, "error", output.one_line(error), values, extra=extra)
    if made_now is not None:
        missed, text, measured = made_now.missed, made_now.missed_text(), made_now.measured
        lines = made_now.warnings + made_now.notes
    elif job.skin is not None:  # kept with --skin: what its skin and pieces measure is in its files
        missed, text, measured, lines = [], "", None, list(job.warnings)
    else:
        missed = synthesized_misses(job, measured)
        text, lines = missed_text(missed) if missed else "", list(job.warnings)
    if missed:
        output.say(f"{PROG} batch: line {line}: warning: {text}")
    skin = made_now.skin if made_now is not None else None
    report = reporting.report_row(
        line,
        name,
        "missed" if missed else "ok",
        "; ".join(lines + notes + [text][: bool(missed)] + (["kept (--resume)"] if kept else [])),
        values,
        measured,
        listed,
        row.reference.name,
        extra,
        skin_settings=skin.settings if skin else None,
        skin_measured=skin.measured if skin else None,
    )
    report["kept"], report["redone"] = kept, bool(changed)
    if bundles is not None:
        bundles.mark(row.reference, result, i, name)
    return report


class Bundles:
    """``--format npz``: one streamed batch file per reference set (``BatchFileWriter``), fed a chunk at a time
    with the rows whose files were written, in the CSV's order."""

    def __init__(self, folder, suffix, mode, tagged, made=None):
        self.folder, self.suffix, self.mode, self.tagged, self.made = folder, suffix, mode, tagged, made
        self.writers, self.marked = {}, []

    def path_of(self, reference):
        tag = f"-{reference.name}" if self.tagged else ""
        return os.path.join(self.folder, f"mannequins{tag}{self.suffix}.npz")

    def mark(self, reference, result, i, name):
        self.marked.append((reference, result, i, name))

    def add(self, chunk):
        """The rows of ``chunk`` marked, into their files (the rows of one result at once); every reference set
        the chunk synthesized from has its file, whether or not a row of it was written."""
        for reference, _ in chunk.groups:
            self._writer(reference)
        runs = {}
        for reference, result, i, name in self.marked:
            runs.setdefault((id(reference), id(result)), (reference, result, [], []))
            runs[id(reference), id(result)][2].append(i)
            runs[id(reference), id(result)][3].append(name)
        self.marked = []
        for reference, result, rows, names in runs.values():
            writer = self._writer(reference)
            rows = np.array(rows)
            with writing.writing(writer.path):
                writer.add(
                    names,
                    result.requests[rows],
                    result.measured[rows],
                    result.factors[rows],
                    result.converged[rows],
                    result.rotation[rows],
                    result.center[rows],
                    result.semi_axes[rows],
                    None if result.joints is None else result.joints[rows],
                )

    def _writer(self, reference):
        if id(reference) not in self.writers:
            path = self.path_of(reference)
            with writing.writing(path):
                made_from = self.made.bundle_record(reference) if self.made is not None else None
                self.writers[id(reference)] = BatchFileWriter(
                    path, reference.topology, self.mode, JOINT_NAMES, made_from=made_from
                )
        return self.writers[id(reference)]

    def finish(self):
        for writer in self.writers.values():
            with writing.writing(writer.path):
                writer.finish()

    def discard(self):
        for writer in self.writers.values():
            writer.discard()
