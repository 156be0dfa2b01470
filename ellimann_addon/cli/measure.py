"""``ellimann measure``: m_T of a .json mannequin (no Blender) or of a .blend (Blender)."""

import json
import os
import sys

from ..core.constants import MEASUREMENT_LABELS, MEASUREMENTS
from ..core.errors import MannequinError
from ..core.mannequin import Mannequin
from . import common
from .common import UsageError


def add_parser(commands):
    measure = commands.add_parser("measure", help="m_T of a mannequin file",
                                  description="Tailor measurements (m_T) of a .json or .blend mannequin, in cm.")
    measure.add_argument("file", metavar="FILE")
    measure.add_argument("--json", action="store_true",
                         help='print exactly {"He": …, "Sh": …, "Br": …, "Wa": …, "Hi": …}')
    measure.add_argument("--collection", help="the mannequin collection to measure in a .blend holding several")
    common.add_references(measure, "measure at the section heights of this reference set instead of those the "
                                   "mannequin records (its own set's; female for files that record none)",
                          shipped="female or male")
    common.add_verbose(measure)
    measure.set_defaults(run=run, blender=needs_blender)


def needs_blender(args):
    """What needs Blender in this command (None: nothing)."""
    return f"reading {args.file}" if os.path.splitext(args.file)[1].lower() == ".blend" else None


def run(args):
    path = args.file
    kind = os.path.splitext(path)[1].lower()
    if not os.path.isfile(path):
        raise UsageError(f"{path}: no such file")
    if kind == ".json":
        mannequin = load_json_mannequin(path)
    elif kind == ".blend":
        mannequin = load_blend_mannequin(path, args.collection)
    else:
        raise UsageError(f"FILE must be a .json or .blend mannequin, got {path!r}")
    if args.references:
        reference = common.references(args)
        mannequin = mannequin.copy(reference_set=reference.name, section_fractions=reference.section_fractions)
    values = mannequin.measure()
    if args.json:
        try:
            text = json.dumps({key: round(values[key], 4) for key in MEASUREMENTS}, allow_nan=False)
        except ValueError:  # NaN or infinity: not JSON, and not a measurement
            raise UsageError(f"{path}: m_T is not finite ({common.format_me(values.values())} cm)") from None
        print(text)
    else:
        common.say(f"{mannequin.name or path}: m_T", file=sys.stdout)
        for key in MEASUREMENTS:
            print(f"  {key} {MEASUREMENT_LABELS[key]:<17} {values[key]:9.2f} cm")
    return 0


def load_json_mannequin(path):
    """Mannequin.load, its error naming the file."""
    try:
        return Mannequin.load(path)
    except MannequinError as error:
        text = common.one_line(error)
        raise UsageError(text if path in text else f"{path}: {text}") from None


def load_blend_mannequin(path, collection_name=None):
    bpy = common.ensure_registered("reading a .blend file")
    from ..blender.bridge.convert import collection_to_mannequin, mannequin_collections
    from ..blender.services.chatter import blender_output

    try:
        with blender_output():
            bpy.ops.wm.open_mainfile(filepath=os.path.abspath(path), load_ui=False)
    except RuntimeError as error:
        raise UsageError(f"{path}: Blender cannot open it ({common.one_line(error)})") from None
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
