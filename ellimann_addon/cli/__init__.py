"""The ElliMann command line: one ``main(argv) -> int`` behind three entry points.

- ``ellimann …`` (``pip install .``: :func:`main_exit`) and ``python -m ellimann_addon …``
- ``blender --background --command ellimann …`` (registered by ``blender/cli_command.py``)

Subcommands, a module each: ``synth`` (one mannequin), ``batch`` (a CSV of measurements), ``sizes`` (an avatar per
person or size of a measurement file: .vit, .vst, a FreeSewing set, a size chart; its report: ``sizes_report``),
``pose`` (a mannequin in a pose), ``measure`` (m_T of a file; ``measurement_files``: written back as a .vit,
FreeSewing set or chart row), ``demo`` (the paper's Table 2.5 mannequins with a report and a line-up picture),
``drape`` (a garment on a mannequin with Blender's cloth simulation), ``references`` (build or check a reference
set) and ``population`` (rows sampled from a survey's statistics, for ``batch``); ``distributed`` runs ``batch
--dask``; what they share is in ``output`` (printed lines, exit codes), ``arguments`` (parser pieces),
``skin_options`` (``--skin``: its options and the settings they ask for), ``avatar_options`` (an FBX avatar's),
``writing`` (files, the output folder), ``reporting`` (the report CSV) and ``provenance`` (what a batch row's files
were made from, for ``--resume``). This package needs numpy only: Blender (the bpy module and
``ellimann_addon.blender``) is imported only when a .blend, .glb or .fbx file, a drape or a picture is involved,
and a command that needs it without it is refused in one line. What Blender prints is captured (``chatter``) and
shown only with ``--verbose``. User mistakes end with a one-line reason and a non-zero exit code:
1 for bad input or a failed row, 2 for a malformed command line, 3 when exact mode missed a request (the files are
written), 130 when interrupted (Ctrl-C).
"""

import argparse
import contextlib
import sys

from ..core.constants import VERSION
from ..core.errors import ElliMannError
from . import batch, demo, drape, measure, output, population, pose, references, sizes, synth
from .output import INTERRUPTED, MISSED, PROG, UsageError, one_line, say
from .writing import blender_available, no_blender

__all__ = ["INTERRUPTED", "MISSED", "PROG", "UsageError", "build_parser", "main", "main_exit"]
SUBCOMMANDS = (synth, batch, sizes, pose, measure, demo, drape, references, population)


def build_parser():
    parser = argparse.ArgumentParser(
        prog=PROG,
        description="ElliMann: measurement-driven mannequins from convex ellipsoids and cushions (measurements in cm).",
    )
    parser.add_argument("--version", action="version", version=f"{PROG} {VERSION}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for command in SUBCOMMANDS:
        command.add_parser(commands)
    return parser


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
        needs = args.blender(args)  # what of this command needs Blender from the start, if anything (a job's
        if needs and not blender_available():  # files are checked by the job: synth, pose, batch)
            raise no_blender(needs)
        with contextlib.ExitStack() as stack:
            capture = lambda: stack.enter_context(_captured(args.verbose))  # noqa: E731
            if needs:
                capture()
            with output.blender_capture(capture):  # a job's first Blender call (writing a .glb) starts it
                return args.run(args)
    except (ElliMannError, OSError) as error:
        say(f"{PROG} {args.command}: error: {one_line(error)}")
        return 1
    except KeyboardInterrupt:
        say(f"{PROG} {args.command}: interrupted")
        return INTERRUPTED


def _captured(show):
    """What Blender prints, kept out of ElliMann's lines (``blender.services.chatter.program``): from the start of a
    command that needs Blender, else from its first Blender call, if any (a job writing a .glb)."""
    from ..blender.services.chatter import program

    return program(show=show)


def main_exit(argv=None):
    """The ``ellimann`` console command: :func:`main`, then leave (skipping Blender 4.x's teardown, which
    crashes there once bpy was loaded: ``blender.services.teardown.exit_with``)."""
    code = main(argv)
    if "bpy" in sys.modules:
        from ..blender.services import teardown

        teardown.exit_with(code)
    sys.exit(code)
