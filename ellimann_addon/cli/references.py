"""``ellimann references``: build a reference set from a traced Base Mannequin and N >= 3 body meshes
(``build``), or check a reference-set folder (``check``). numpy only."""

import argparse
import dataclasses
import hashlib
import os
import pathlib
import sys

from ..core.mannequin.clean import asymmetry
from ..core.measurements import MEASUREMENTS
from ..core.synthesis.manifest import STEM, read_manifest
from ..core.synthesis.reference_set import load_reference_set
from . import arguments, output, writing
from .measure import load_json_mannequin
from .output import PROG, UsageError

ACCEPT = 5e-3  # what ``check`` lets an RM's m_T differ from its targets by (the builder's accept tolerance)


def add_parser(commands):
    references = commands.add_parser(
        "references",
        help="build or check a reference set",
        description="Reference sets: the Reference Mannequins synthesis interpolates.",
    )
    actions = references.add_subparsers(dest="action", metavar="ACTION", required=True)
    build = actions.add_parser(
        "build",
        help="Reference Mannequins from a traced Base Mannequin and N >= 3 bodies",
        description="Fit the Base Mannequin's traced parts in every body (OBJ meshes of the traced mesh's "
        "topology, Y up as Blender exports them unless --up z), refine each until m_T meets its targets, clean "
        "them together and write a reference-set folder (the RMs' JSON, the base and reference_set.json).",
    )
    build.add_argument(
        "--base",
        required=True,
        metavar="BASE.json",
        help="the Base Mannequin, with its recorded "
        "selections (traced with Fit Ellipsoid); the set is measured at the section heights it "
        "records (its own set's)",
    )
    build.add_argument(
        "--bodies",
        required=True,
        nargs="+",
        metavar="BODY.obj",
        help="N >= 3 body meshes; each file's stem names its Reference Mannequin",
    )
    arguments.add_mesh_axes(build, "--bodies", default_up="y")
    build.add_argument(
        "--targets",
        required=True,
        metavar="TARGETS.csv",
        help="a 'name' column (the bodies' file stems) and a column per measurement: "
        f"{', '.join(MEASUREMENTS)} in cm (or target_He, ...)",
    )
    output = build.add_mutually_exclusive_group(required=True)  # -o/--output as every command; --out: its old name
    output.add_argument("-o", "--output", metavar="DIR", help="the reference-set folder to write")
    output.add_argument("--out", dest="output", metavar="DIR", help=argparse.SUPPRESS)
    build.add_argument("--name", help="the set's name (default: the folder's name)")
    build.add_argument("--sex", choices=("female", "male"), help="the set's sex, if it has one")
    build.add_argument(
        "--workers",
        type=int,
        default=os.cpu_count() or 1,
        metavar="N",
        help="processes fitting bodies at once (default: the CPUs, %(default)s here; the result is the same for any N)",
    )
    build.add_argument(
        "--reference",
        metavar="STEM",
        help="the body whose RM the others' axes are labelled against (default: the one nearest the targets' mean)",
    )
    arguments.add_verbose(build)
    build.set_defaults(run=run_build, blender=lambda args: None)
    check = actions.add_parser(
        "check",
        help="check a reference-set folder",
        description="Validity, ranges, symmetry and how each RM meets its targets.",
    )
    check.add_argument(
        "folder",
        metavar="DIR",
        help="a reference-set folder, or a shipped set's name (female, male, female-fine, male-fine)",
    )
    arguments.add_verbose(check)
    check.set_defaults(run=run_check, blender=lambda args: None)


def run_build(args):
    from ..core.fitting.body_mesh import BodyMeshError, read_obj  # the builder, loaded when it runs
    from ..core.fitting.reference_build import (
        MIN_BODIES,
        build_reference_set,
        read_targets,
        traced_mesh,
        validate_inputs,
    )
    from ..core.synthesis.bodies import SKELETON_FILE, BodiesError, shipped_topology_labels, skeleton_joints

    out = pathlib.Path(args.output)
    base = load_base(args.base)
    base_stem = pathlib.Path(args.base).stem
    stems = [pathlib.Path(p).stem for p in args.bodies]
    if base_stem in stems or not STEM.match(base_stem):
        base_stem = "base_mannequin"
    for path in args.bodies:
        if not STEM.match(pathlib.Path(path).stem):
            raise UsageError(f"{path}: its stem must be letters, digits, _ . - (it names the RM's file)")
    targets = read_targets(args.targets)
    if args.workers < 1:
        raise UsageError(f"--workers must be 1 or more, got {args.workers}")
    if len(args.bodies) < MIN_BODIES:  # before reading any mesh
        raise UsageError(f"--bodies: a reference set needs at least {MIN_BODIES} bodies, got {len(args.bodies)}")
    try:
        bodies = [read_obj(path, args.up, args.unit) for path in args.bodies]
        skeletons = skeleton_joints(pathlib.Path(args.bodies[0]).parent / SKELETON_FILE)
    except (BodyMeshError, BodiesError) as error:
        raise UsageError(output.one_line(error)) from None
    bodies = [dataclasses.replace(body, joints=skeletons.get(body.name, body.joints)) for body in bodies]
    validate_inputs(base, bodies, targets)  # before the folder is made: bad input writes nothing
    labels = shipped_topology_labels(bodies[0].faces)  # bodies of the body model's topology: kept for the body skin
    writing.output_folder(str(out), "references build")

    def progress(fraction, text):
        output.say(f"{PROG} references build: {fraction:4.0%} {text}", file=sys.stderr)

    built = build_reference_set(
        base,
        bodies,
        targets,
        progress=progress,
        reference=args.reference,
        workers=args.workers,
        name=args.name or out.resolve().name,
        sex=args.sex,
        base_stem=base_stem,
        body_labels=labels,
        provenance={
            "built_by": f"{PROG} references build",
            "base": {"file": pathlib.Path(args.base).name, **traced_mesh(base)},
            "bodies": {
                b.name: {"file": pathlib.Path(p).name, "sha256": _sha256(p)} for b, p in zip(bodies, args.bodies)
            },
            "bodies_read_as": {"up": args.up, "unit": args.unit},
        },
    )
    with writing.writing(str(out), folder=True):
        built.write(out)
    report = built.report
    for stem in stems:
        key, error = report.worst(stem)
        fill = report.fill.get(stem, {}).get("ellipsoids")
        filled = f", fills {fill['coverage']:.1%} of its body (excess {fill['excess']:.1%})" if fill else ""
        print(f"{stem}: worst m_T error {error:+z.4%} ({key}){filled}")
    print(f"wrote {len(stems)} Reference Mannequins, {base_stem}.json and reference_set.json to {out}")
    if built.bodies is None:
        print("the bodies are not the body model's topology: the set's skin is the smooth skin over its pieces")
    else:
        joints = "their skeleton file's" if skeletons else "regressed from the labels"
        space = ", their body space (body_space.npz)" if built.space is not None else ""
        print(f"kept the bodies for the body skin (bodies.npz{space}; the joints {joints})")
    return 0


def load_base(path):
    if not pathlib.Path(path).is_file():
        raise UsageError(f"{path}: no such file")
    return load_json_mannequin(path)


def _sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def check_folder(folder):
    """(lines, problems) of ``references check``: one line per RM, one per problem found."""
    from ..core.fitting.reference_build import cleanliness_problems, relative_errors

    reference = load_reference_set(folder)  # validity: files, topology, symmetry, distinct measurements
    manifest = read_manifest(folder)
    lines, problems = [], []
    layout = "manifest reference_set.json" if manifest else "legacy layout (no reference_set.json)"
    lines.append(f"{folder}: '{reference.name}', {len(reference)} RMs, {layout}")
    for key in MEASUREMENTS:
        lo, hi = reference.ranges[key]
        a_lo, a_hi = reference.absurd_limits[key]
        values = reference.measurements[:, MEASUREMENTS.index(key)]
        if not a_lo <= lo <= hi <= a_hi:
            problems.append(f"ranges_cm {key} [{lo:g}, {hi:g}] is not within absurd_limits_cm [{a_lo:g}, {a_hi:g}]")
        if values.min() < lo - 1e-9 or values.max() > hi + 1e-9:
            problems.append(
                f"ranges_cm {key} [{lo:g}, {hi:g}] does not hold the RMs' {key} "
                f"({values.min():g} to {values.max():g} cm)"
            )
    targets = manifest.targets_cm if manifest else {}
    for name, rm in zip(reference.names, reference.mannequins):
        wanted = targets.get(name) or rm.measurements
        errors = relative_errors(rm.measure(), wanted)
        key = max(errors, key=lambda k: abs(errors[k]))
        lines.append(f"{name}: worst m_T error {errors[key]:+z.4%} ({key}), asymmetry {asymmetry(rm) * 1e3:.2g} mm")
        if abs(errors[key]) > ACCEPT:
            problems.append(f"{name}: m_T {key} is off its target by {errors[key]:+z.3%} (accepted {ACCEPT:.1%})")
        problems += [f"{name}: {text}" for text in cleanliness_problems(rm, 1e-6)]
    return lines, problems


def run_check(args):
    from ..core.synthesis.shipped import SHIPPED_SETS

    folder = pathlib.Path(args.folder)
    if not folder.is_dir() and args.folder.casefold() in SHIPPED_SETS:  # a shipped set by its name
        folder = SHIPPED_SETS[args.folder.casefold()]
    if not folder.is_dir():
        raise UsageError(f"{args.folder}: no such folder (nor a shipped set: {', '.join(SHIPPED_SETS)})")
    lines, problems = check_folder(folder)
    for line in lines:
        print(line)
    for problem in problems:
        output.say(f"{PROG} references check: error: {problem}")
    return 1 if problems else 0
