"""What the subcommands share: the one-line errors and exit codes, ElliMann's printed lines, writing files
(core formats without Blender, Blender's through ``blender.services.files`` only when asked), the output folder, the
report CSV and the progress line. Blender (bpy, ``ellimann_addon.blender``) is imported only inside functions
that need it."""

import argparse
import contextlib
import csv
import importlib.util
import io
import math
import os
import re
import sys
import tempfile
import time

from ..core.constants import MEASUREMENTS
from ..core.errors import ElliMannError, ReferenceSetError, one_line  # noqa: F401  (one_line: common.one_line)
from ..core.files import atomic_write_text, clean_stale_temporaries
from ..core.formats.core_writers import core_format, write_core_file
from ..core.formats.table import FORMATS, format_of
from ..core.measure.tailor import measurement_line
from ..core.synthesis.options import SYNTHESIS, SynthesisOptions
from ..core.synthesis.refine import EXACT_TOLERANCE
from ..core.synthesis.request import relative_error

PROG = "ellimann"
MISSED = 3  # exit code: written, but exact mode missed a requested measurement by more than its tolerance
INTERRUPTED = 130  # exit code after Ctrl-C, as shells report SIGINT


class UsageError(ElliMannError):
    """A mistake on the command line or in an input file, reported in one line."""


# ------------------------------------------------------------------------------------------------ printing


_UNPRINTABLE = re.compile(r"[\x00-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028-\u202e\u2066-\u2069]")


def printable(text):
    """``text`` with control characters (terminal escapes, carriage returns, bidi overrides) as \\x1b, \\n…"""
    return _UNPRINTABLE.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), str(text))


def say(text, file=None, end="\n"):
    """Print one of ElliMann's lines (stderr unless ``file``), escaping what a terminal would act on."""
    print(printable(text), file=file or sys.stderr, end=end, flush=True)


def format_me(values):
    """The m_T line (``core.measure.tailor.measurement_line``)."""
    return measurement_line(values)


# ------------------------------------------------------------------------------------------------ parser pieces


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


def add_references(parser, what, shipped="female (the default) or male"):
    parser.add_argument(
        "--references",
        metavar="NAME_OR_DIR",
        help=f"{what}: a shipped set, {shipped}, or a folder of Reference Mannequin .json files "
        "(with its reference_set.json manifest)",
    )


def add_pose_option(parser):
    """--pose NAME (a standard pose, or a pose .json) and --fps."""
    from ..core.pose.standard import POSE_NAMES, WALK_FPS

    parser.add_argument(
        "--pose",
        metavar="NAME",
        help=f"write the mannequin posed: {', '.join(POSE_NAMES)} (walk: "
        "an animation, in .json and .xml as its frames), or a pose .json file; measurements stay "
        "the rest pose's",
    )
    parser.add_argument("--fps", type=number, default=WALK_FPS, help=f"frames per second of walk (default {WALK_FPS})")


def check_pose_argument(args, kinds):
    """Refuse, before any work is done, an unknown pose name, a pose file that cannot be read and an animation
    for a format of ``kinds`` that holds none. Returns the frames of a pose file (None otherwise)."""
    from ..core.pose.standard import MOTIONS, check_pose_name

    if args.pose is None:
        return None
    frames = None
    if args.pose.lower().endswith(".json"):
        from ..core.formats.posed_files import read_pose

        frames = read_pose(args.pose)
    else:
        check_pose_name(args.pose)
    still = [FORMATS[k] for k in kinds if k in FORMATS and not FORMATS[k].animated]  # (npz: batch's own bundle)
    if still and (args.pose in MOTIONS or (frames is not None and len(frames) > 1)):
        raise UsageError(
            f"--pose {args.pose} is an animation and a .{still[0].extension} file holds none; write "
            f"{', '.join('.' + f.extension for f in FORMATS.values() if f.animated)}"
        )
    return frames


def pose_frames(args, mannequin, frames=None):
    """The frames of ``--pose`` for ``mannequin`` (None without --pose): ``frames`` read from a pose file, or the
    standard pose made on its joints; ElliMannError naming the joint (and frame) of one beyond its limits."""
    from ..core.pose.kinematics import check_limits, require_joints
    from ..core.pose.standard import standard_motion

    if args.pose is None:
        return None
    joints = require_joints(mannequin)
    frames = frames if frames is not None else standard_motion(args.pose, joints, args.fps)
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


# ------------------------------------------------------------------------------------------------ Blender


def blender_available():
    """Whether the bpy module can be imported (without importing it)."""
    if "bpy" in sys.modules:
        return sys.modules["bpy"] is not None
    try:
        return importlib.util.find_spec("bpy") is not None
    except (ImportError, ValueError):
        return False


def no_blender(what):
    return UsageError(
        f"{what} needs Blender: the bpy module is not installed (pip install bpy, or run "
        f"blender --background --command {PROG} …)"
    )


def ensure_registered(what="this"):
    """Import bpy; under ``python -m`` register the add-on once so ElliMann's properties exist."""
    from ..blender.services.chatter import blender_output

    with blender_output():
        try:
            import bpy
        except ImportError:
            raise no_blender(what) from None

        if not hasattr(bpy.types.Collection, "ellimann"):
            from .. import register

            register()
    return bpy


# ------------------------------------------------------------------------------------------------ writing


def output_kind(path):
    kind = format_of(path)
    if kind is None:
        raise UsageError(f"OUT must end in .blend, .glb, .obj, .json or .xml (MJCF), got {path!r}")
    return kind.name


def extension(kind):
    return FORMATS[kind].extension


def write(mannequin, paths, measured, cushions, frames=None, fps=None):
    """Write every path (format from the extension); Blender is loaded only for .blend and .glb. ``frames``: the
    pose (a list of core.pose.kinematics.Pose) to write the mannequin in, if any.

    A path that cannot be written raises UsageError naming it (not the temporary file behind it).
    """
    if frames is not None:
        return write_posed(mannequin, paths, cushions, frames, fps, measured)
    for path in paths:
        if core_format(path):
            with writing(path):
                write_core_file(mannequin, path, cushions)
    blender = [p for p in paths if core_format(p) is None]
    if blender:
        ensure_registered(f"writing {blender[0]}")
        from ..blender.services.files import write_mannequin

        try:
            write_mannequin(mannequin, blender, measured, cushions)
        except OSError as error:  # atomic_output names the file that failed
            if error.filename is None:
                raise
            raise cannot_write(error.filename, error) from None
    return paths


def write_posed(mannequin, paths, cushions, frames, fps, measured=None):
    """:func:`write` of a posed mannequin: .json, .xml and .obj by the core (core.formats.posed_files), .blend and
    .glb by the Blender rig (``blender.services.posing.write_posed``)."""
    from ..core.formats.posed_files import write_posed as write_core_posed

    blender = [p for p in paths if format_of(p).needs_blender_for(True)]
    for path in [p for p in paths if p not in blender]:
        with writing(path):
            write_core_posed(mannequin, frames, path, cushions, fps)
    if blender:
        ensure_registered(f"writing {blender[0]}")
        try:
            from ..blender.services.posing import write_posed as write_blender_posed
        except ImportError:
            raise UsageError(
                f"writing a posed {blender[0]} needs ElliMann's Blender rig, which this build lacks; "
                "write .json, .xml or .obj"
            ) from None
        write_blender_posed(mannequin, frames, blender, cushions, fps, measured)
    return paths


@contextlib.contextmanager
def writing(target, folder=False):
    """Turn an OSError while writing ``target`` (a file, or a folder with ``folder``) into one line naming it."""
    try:
        yield
    except OSError as error:
        raise cannot_write(target, error, folder) from None


def cannot_write(target, error, folder=False):
    where = os.path.abspath(target if folder else os.path.dirname(os.path.abspath(target)))
    blocker = _file_in_the_way(where)
    what = f"the folder {target}" if folder else target
    if not folder and os.path.isdir(target):
        reason = "it is a folder"
    elif blocker is not None:
        reason = "it is a file" if blocker == where and folder else f"{blocker} is a file, not a folder"
    else:
        reason = error.strerror or one_line(error)
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


def output_folder(folder, command):
    """Make the output folder and check that files can be created in it, before any work is done; remove
    the temporaries a killed run of ElliMann left there (not those of one still running)."""
    with writing(folder, folder=True):
        os.makedirs(folder, exist_ok=True)
        with tempfile.TemporaryFile(prefix=".ellimann-", dir=folder):
            pass
    removed = clean_stale_temporaries(folder)
    if removed:
        say(f"{PROG} {command}: removed {len(removed)} temporary file(s) an interrupted run left in {folder}")


# ------------------------------------------------------------------------------------------------ exact mode


def misses(measured, requested):
    """The requested measurements exact mode missed by more than its tolerance (EXACT_TOLERANCE, the
    criterion it stops at): [(key, m_T cm, requested cm, error %)]."""
    return [
        (key, float(m), float(r), abs(m - r) / r * 100.0)
        for key, m, r in zip(MEASUREMENTS, measured, requested)
        if abs(math.log(max(float(m), 1e-12) / float(r))) > EXACT_TOLERANCE
    ]


def missed_text(missed):
    return (
        "exact mode missed "
        + ", ".join(f"{key} by {error:.2f}% (m_T {m:.2f} cm for {r:g} cm)" for key, m, r, error in missed)
        + f" (tolerance {EXACT_TOLERANCE * 100:g}%; the file is the closest it found)"
    )


# ------------------------------------------------------------------------------------------------ report CSV


REPORT_COLUMNS = (
    ["line", "name", "status", "message"]
    + list(MEASUREMENTS)
    + [f"{k}_measured" for k in MEASUREMENTS]
    + [f"{k}_error_pct" for k in MEASUREMENTS]
    + ["files", "references"]
)


def report_row(line, name, status, message, requested=None, measured=None, paths=(), references=""):
    """One report row; text from the CSV or messages is made safe for spreadsheets and terminals (:func:`cell`).
    ``references``: the reference set the row was synthesized from (its name)."""
    row = {
        "line": line,
        "name": cell(name),
        "status": status,
        "message": cell(message or ""),
        "files": cell(" ".join(paths)),
        "references": cell(references),
    }
    error = relative_error(measured, requested) if measured is not None else None
    for i, key in enumerate(MEASUREMENTS):
        row[key] = f"{requested[i]:g}" if requested is not None else ""
        row[f"{key}_measured"] = f"{measured[i]:.4f}" if measured is not None else ""
        row[f"{key}_error_pct"] = f"{error[i]:.4f}" if error is not None else ""
    return row


def cell(text):
    """A report cell: control characters escaped (:func:`printable`), and text a spreadsheet would take for
    a formula (starting with =, +, - or @) neutralised with a leading apostrophe, as OWASP recommends."""
    text = printable(text)
    return "'" + text if text[:1] in ("=", "+", "-", "@") else text


def report_csv(rows):
    stream = io.StringIO()
    writer = csv.DictWriter(stream, fieldnames=REPORT_COLUMNS, lineterminator="\n", extrasaction="ignore")
    writer.writeheader()
    writer.writerows(rows)
    return stream.getvalue()


def write_text(path, text):
    with writing(path):
        atomic_write_text(path, text)


class Progress:
    """One progress line on stderr: count, rate and time left, rewritten in place on a terminal, every ~5% in a
    log; nothing with ``quiet`` (``-q``)."""

    def __init__(self, total, command, every=None, quiet=False):
        self.total, self.count, self.start = total, 0, time.perf_counter()
        self.command, self.quiet = command, quiet
        self.stream = sys.stderr  # ElliMann's stderr, also from inside blender_output() (where sys.stderr is Blender's)
        self.tty = self.stream.isatty()
        self.every = every or max(1, total // 20)
        self.shown = 0.0  # when the line was last rewritten (a terminal gets at most ~10 a second)

    def step(self, name, count=None):
        """One more done (``name``: what), or ``count`` done so far; repeated counts are ignored."""
        if count is not None and count <= self.count:
            return
        previous = self.count
        self.count = self.count + 1 if count is None else count
        if self.quiet:
            return
        now = time.perf_counter()
        due = (
            (now - self.shown >= 0.1 or self.count == self.total)
            if self.tty
            else (self.count // self.every > previous // self.every or self.count == self.total)
        )
        if due:
            self.shown = now
            text = printable(f"{PROG} {self.command}: {self.line(now)} {name}")
            print(
                f"\r{text[:100]:<100}" if self.tty else text, end="" if self.tty else "\n", file=self.stream, flush=True
            )

    def line(self, now):
        """ "120/2000 (41.5/s, 45 s left)": count, rate and the time left at that rate."""
        elapsed = max(now - self.start, 1e-9)
        rate = self.count / elapsed
        left = (self.total - self.count) / rate if rate > 0 else 0.0
        return f"{self.count}/{self.total} ({rate:.1f}/s, {duration(left)} left)"

    def done(self):
        if self.tty and self.total and not self.quiet:
            print(file=self.stream)


def duration(seconds):
    """ "45 s", "12 min 5 s", "2 h 3 min": a time left, to the second below a minute."""
    seconds = int(round(seconds))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60} min {seconds % 60} s"
    return f"{seconds // 3600} h {seconds % 3600 // 60} min"
