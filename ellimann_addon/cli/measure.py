"""``ellimann measure``: m_T and the extra measurements of a .json mannequin (no Blender), of a .blend (Blender),
or of a body mesh (.obj / .ply / .stl, no Blender)."""

import json
import math
import os
import sys

from ..core.constants import MEASUREMENT_LABELS, MEASUREMENTS
from ..core.errors import MannequinError
from ..core.fitting.body_mesh import MESH_EXTENSIONS, BodyMeshError, read_body_mesh
from ..core.mannequin.model import Mannequin
from ..core.measure.body import ALL_MEASUREMENTS, measure_body_mesh
from ..core.measure.extra import EXTRA_LABELS, mannequin_extra_measurements
from . import arguments, output, writing
from .output import UsageError

LABELS = {**MEASUREMENT_LABELS, **EXTRA_LABELS}
NECK_TILT_LIMITS = (-45.0, 60.0)  # degrees forward: what --neck-tilt accepts


def add_parser(commands):
    measure = commands.add_parser(
        "measure",
        help="measurements of a mannequin file or a body mesh",
        description="Tailor measurements (m_T and the extra ones, docs/measurements.md) of a "
        ".json or .blend mannequin or of an upright A-pose body mesh "
        "(.obj, .ply, .stl), in cm.",
    )
    measure.add_argument("file", metavar="FILE")
    measure.add_argument(
        "--json",
        action="store_true",
        help='print {"He": …, "Sh": …, "Br": …, "Wa": …, "Hi": …, "neck": …, …} (a body mesh: '
        "only the measurements that could be taken)",
    )
    arguments.add_mesh_axes(measure, "a body mesh")
    measure.add_argument(
        "--neck-tilt",
        type=float,
        metavar="DEG",
        help="a body mesh: measure the neck square to an axis leaning DEG forward from vertical, "
        f"{NECK_TILT_LIMITS[0]:g} to {NECK_TILT_LIMITS[1]:g} (a mannequin's exported pieces: its joints' tilt); "
        "default: the tilt a tape drawn tight round the neck settles at",
    )
    measure.add_argument("--collection", help="the mannequin collection to measure in a .blend holding several")
    arguments.add_references(
        measure,
        "measure at the section heights of this reference set instead of those the "
        "mannequin records (its own set's; female for files that record none)",
        shipped="female, male, female-fine or male-fine (of the mannequin's own topology)",
    )
    arguments.add_verbose(measure)
    measure.set_defaults(run=run, blender=needs_blender)


def needs_blender(args):
    """What needs Blender in this command (None: nothing)."""
    return f"reading {args.file}" if os.path.splitext(args.file)[1].lower() == ".blend" else None


def run(args):
    path = args.file
    kind = os.path.splitext(path)[1].lower()
    if not os.path.isfile(path):
        raise UsageError(f"{path}: no such file")
    if args.neck_tilt is not None:
        low, high = NECK_TILT_LIMITS
        if kind not in MESH_EXTENSIONS:
            raise UsageError(f"--neck-tilt is for a body mesh: a mannequin's neck leans as its joints do ({path})")
        if not (math.isfinite(args.neck_tilt) and low <= args.neck_tilt <= high):
            raise UsageError(f"--neck-tilt must be {low:g} to {high:g} degrees, got {args.neck_tilt:g}")
    if kind in MESH_EXTENSIONS:
        values, problems = measure_mesh_file(path, args)
        if not values:
            raise UsageError(f"{path}: {problems[0]}")
        for problem in problems:
            output.say(f"{output.PROG} measure: warning: {path}: {problem}")
        _print(values, args.json, path, f"{path}: body mesh")
        return 0
    if kind == ".json":
        mannequin = load_json_mannequin(path)
    elif kind == ".blend":
        mannequin = load_blend_mannequin(path, args.collection)
    else:
        raise UsageError(
            f"FILE must be a .json or .blend mannequin or a {'/'.join(MESH_EXTENSIONS)} body mesh, got {path!r}"
        )
    if args.references:
        reference = arguments.references(args)
        reference.check_topology(mannequin, path)
        mannequin = mannequin.copy(reference_set=reference.name, section_fractions=reference.section_fractions)
    values = dict(mannequin.measure())
    values.update(mannequin_extra_measurements(mannequin))
    _print(values, args.json, path, f"{mannequin.name or path}: m_T and more")
    return 0


def measure_mesh_file(path, args):
    """({key: cm} of what could be measured, [problem lines]) of a body mesh file."""
    try:
        vertices, faces = read_body_mesh(path, args.up, args.unit)
    except BodyMeshError as error:
        raise UsageError(output.one_line(error)) from None
    fractions = arguments.references(args).section_fractions if args.references else None
    tilt = getattr(args, "neck_tilt", None)  # measure's own option (synth --from has none)
    result = measure_body_mesh(vertices, faces, fractions, None if tilt is None else math.radians(tilt))
    return result.values, result.problems


def _print(values, as_json, path, title):
    """The measurements, as JSON or a table; non-finite ones: the five refuse, an extra one (a mannequin without
    arm or leg pieces) is left out with a warning."""
    five = [values[key] for key in MEASUREMENTS if key in values]
    if not all(math.isfinite(value) for value in five):
        raise UsageError(f"{path}: m_T is not finite ({output.format_me(five)} cm)")
    lost = [key for key in ALL_MEASUREMENTS if key in values and not math.isfinite(values[key])]
    if lost:
        output.say(f"{output.PROG} measure: warning: {path}: {', '.join(lost)} cannot be taken (no such pieces)")
    keys = [key for key in ALL_MEASUREMENTS if key in values and key not in lost]
    if as_json:
        print(json.dumps({key: round(values[key], 4) for key in keys}))
    else:
        output.say(title, file=sys.stdout)
        for key in keys:
            print(f"  {key} {LABELS[key]:<17} {values[key]:9.2f} cm")


def load_json_mannequin(path):
    """Mannequin.load, its error naming the file."""
    try:
        return Mannequin.load(path)
    except MannequinError as error:
        text = output.one_line(error)
        raise UsageError(text if path in text else f"{path}: {text}") from None


def load_blend_mannequin(path, collection_name=None):
    bpy = writing.ensure_registered("reading a .blend file")
    from ..blender.bridge.convert import collection_to_mannequin, mannequin_collections
    from ..blender.services.chatter import blender_output

    try:
        with blender_output():
            bpy.ops.wm.open_mainfile(filepath=os.path.abspath(path), load_ui=False)
    except RuntimeError as error:
        raise UsageError(f"{path}: Blender cannot open it ({output.one_line(error)})") from None
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
