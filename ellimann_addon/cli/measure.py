"""``ellimann measure``: m_T and the extra measurements of a .json mannequin (no Blender; one that records a skin:
its pieces' and, labelled apart, its skin's, made again as the file records it), of a .blend (Blender), of a .glb
(what its extras record, no Blender) or of a body mesh (.obj / .ply / .stl, no Blender); with
``--write-measurements``, written back as a .vit, a FreeSewing set or a chart row (``measurement_files``)."""

import json
import math
import os
import sys

from ..core.errors import MannequinError
from ..core.mannequin.model import Mannequin
from ..core.measure.body import MESH_EXTENSIONS, measure_body_mesh
from ..core.measure.extra import mannequin_extra_measurements
from ..core.measurements import ALL_MEASUREMENTS, MEASUREMENT_LABELS, MEASUREMENTS, measurement_line
from . import arguments, measurement_files, output, writing
from .output import UsageError
from .skin_options import describe

LABELS = {**MEASUREMENT_LABELS, **MEASUREMENT_LABELS}
KEY_WIDTH = max(map(len, ALL_MEASUREMENTS))  # the table's columns line up whatever the keys
LABEL_WIDTH = max(map(len, LABELS.values()))
NECK_TILT_LIMITS = (-45.0, 60.0)  # degrees forward: what --neck-tilt accepts


def add_parser(commands):
    measure = commands.add_parser(
        "measure",
        help="measurements of a mannequin file or a body mesh",
        description="Tailor measurements (m_T and the extra ones, docs/measurements.md) of a "
        ".json or .blend mannequin or of an upright A-pose body mesh "
        "(.obj, .ply, .stl), in cm. A .json that records a skin (synth --skin) gives its pieces' "
        "and its skin's (the skin made again as the file records it, measured on its mesh), "
        "each labelled; a .glb gives the m_T its extras record.",
    )
    measure.add_argument("file", metavar="FILE")
    measure.add_argument(
        "--json",
        action="store_true",
        help='print {"He": …, "Sh": …, "Br": …, "Wa": …, "Hi": …, "neck": …, …} (a body mesh: '
        'only the measurements that could be taken; a .json with a skin adds "skin": {"voxel_mm", "blend", '
        '"He", …}, what the skin measures)',
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
    measurement_files.add_write_options(measure)
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
    measurement_files.check_write(args)
    stem = os.path.splitext(os.path.basename(path))[0]
    if kind in MESH_EXTENSIONS:
        values, problems = measure_mesh_file(path, args)
        if not values:
            raise UsageError(f"{path}: {problems[0]}")
        for problem in problems:
            output.say(f"{output.PROG} measure: warning: {path}: {problem}")
        _print(values, args.json, path, f"{path}: body mesh")
        measurement_files.write_measurements(args, values, stem)
        return 0
    if kind == ".glb":
        return measure_glb(path, args)
    if kind == ".json":
        mannequin = load_json_mannequin(path)
    elif kind == ".blend":
        mannequin = load_blend_mannequin(path, args.collection)
    else:
        raise UsageError(
            f"FILE must be a .json, .blend or .glb mannequin or a {'/'.join(MESH_EXTENSIONS)} body mesh, got {path!r}"
        )
    if args.references:
        reference = arguments.references(args)
        reference.check_topology(mannequin, path)
        mannequin = mannequin.copy(reference_set=reference.name, section_fractions=reference.section_fractions)
    values = dict(mannequin.measure())
    values.update(mannequin_extra_measurements(mannequin))
    skin = skin_values(mannequin, path) if kind == ".json" and mannequin.skin is not None else None
    sex = measurement_files.sex_of(mannequin)
    if skin is None:
        _print(values, args.json, path, f"{mannequin.name or path}: m_T and more")
        measurement_files.write_measurements(args, values, mannequin.name or stem, sex)
        return 0
    settings, skin_measured = skin
    measurement_files.write_measurements(args, skin_measured, mannequin.name or stem, sex)  # the body's surface
    if args.json:
        shown = _shown(values)
        how = {"kind": "body"} if settings.kind == "body" else {"voxel_mm": settings.voxel_mm, "blend": settings.blend}
        shown["skin"] = {**how, **_shown(skin_measured)}
        print(json.dumps(shown))
        return 0
    _print(values, False, path, f"{mannequin.name or path}: its pieces (m_T and more)")
    how = describe(settings).removeprefix("skin ")
    title = f"{mannequin.name or path}: its skin ({how}, made again as the file records it; its mesh)"
    _print(skin_measured, False, path, title)
    return 0


def skin_values(mannequin, path):
    """(SkinSettings, {key: cm}) of the skin a .json records (its ``skin`` section): made again as the file records
    it (a job of the mannequin already made: the body skin from its set's bodies and the request it records, the skin
    over the pieces from the pieces), measured on its mesh as ``synth --skin`` reports it (one not taken is left
    out)."""
    from ..core.errors import ElliMannError
    from ..core.job.make import make
    from ..core.job.request import Request, check
    from ..core.mannequin.skin_record import SkinSettings
    from ..core.skin.measure import body_measurements, mesh_measurements

    settings = SkinSettings.from_dict(mannequin.skin)
    try:
        skin = make(check(Request(mannequin=mannequin, skin=settings))).skin.skin
    except ElliMannError as error:
        raise UsageError(f"{path}: its skin cannot be made again: {output.one_line(error)}") from None
    if settings.kind == "body":
        return settings, dict(skin.measure().values)
    values = mesh_measurements(skin)
    values.update(body_measurements(skin).values)
    return settings, values


def measure_glb(path, args):
    """What a .glb's extras record (``core.formats.glb``, numpy only): its pieces' m_T when it was written."""
    from ..core.formats.glb import read_glb_json, scene_extras, skin_nodes

    if args.references or args.collection:
        raise UsageError(f"{path}: a .glb gives the m_T its extras record; --references and --collection do not apply")
    doc = read_glb_json(path)
    extras = scene_extras(doc, path)
    recorded = extras.get("measured_cm")
    if not isinstance(recorded, dict) or not all(isinstance(recorded.get(key), (int, float)) for key in MEASUREMENTS):
        raise UsageError(f"{path}: its extras record no m_T (measured_cm)")
    values = {key: float(recorded[key]) for key in MEASUREMENTS}
    name = extras.get("name") or path
    _print(values, args.json, path, f"{name}: m_T of its pieces as the file's extras record it")
    stem = os.path.splitext(os.path.basename(path))[0]
    measurement_files.write_measurements(args, values, extras.get("name") or stem)
    skins = skin_nodes(doc)
    if skins and not args.json:
        voxel = skins[0].get("voxel_mm")
        made = f" ({voxel:g} mm)" if isinstance(voxel, (int, float)) else ""
        output.say(
            f"{output.PROG} measure: {path} also holds a skin{made}, whose measurements it does not record: measure "
            "the .json or the skin's .obj written with it",
        )
    return 0


def measure_mesh_file(path, args):
    """({key: cm} of what could be measured, [problem lines]) of a body mesh file."""
    from ..core.fitting.body_mesh import BodyMeshError, read_body_mesh  # a mesh's reader, loaded when one is read
    from ..core.synthesis.bodies import labelled_arms

    try:
        vertices, faces = read_body_mesh(path, args.up, args.unit)
    except BodyMeshError as error:
        raise UsageError(output.one_line(error)) from None
    fractions = arguments.references(args).section_fractions if args.references else None
    tilt = getattr(args, "neck_tilt", None)  # measure's own option (synth --from has none)
    arms = labelled_arms(faces)  # a body of the sets' own topology (a scan's twin): its arms by the labels
    result = measure_body_mesh(vertices, faces, fractions, None if tilt is None else math.radians(tilt), arms)
    return result.values, result.problems


def _print(values, as_json, path, title):
    """The measurements, as JSON or a table; non-finite ones: the five refuse, an extra one (a mannequin without
    arm or leg pieces) is left out with a warning."""
    five = [values[key] for key in MEASUREMENTS if key in values]
    if not all(math.isfinite(value) for value in five):
        raise UsageError(f"{path}: m_T is not finite ({measurement_line(five)} cm)")
    lost = [key for key in ALL_MEASUREMENTS if key in values and not math.isfinite(values[key])]
    if lost:
        output.say(f"{output.PROG} measure: warning: {path}: {', '.join(lost)} cannot be taken (no such pieces)")
    keys = [key for key in ALL_MEASUREMENTS if key in values and key not in lost]
    if as_json:
        print(json.dumps({key: round(values[key], 4) for key in keys}))
    else:
        output.say(title, file=sys.stdout)
        for key in keys:
            print(f"  {key:<{KEY_WIDTH}} {LABELS[key]:<{LABEL_WIDTH}} {values[key]:9.2f} cm")


def _shown(values):
    """{key: cm rounded} of the finite measurements in ``values`` (those not taken left out), as --json prints."""
    return {key: round(values[key], 4) for key in ALL_MEASUREMENTS if key in values and math.isfinite(values[key])}


def load_json_mannequin(path):
    """Mannequin.load, its error naming the file."""
    try:
        return Mannequin.load(path)
    except MannequinError as error:
        text = output.one_line(error)
        raise UsageError(text if path in text else f"{path}: {text}") from None


def load_blend_mannequin(path, collection_name=None):
    bpy = writing.blender_module("reading a .blend file")
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
