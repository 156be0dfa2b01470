"""Build ElliMann's reference data: the Base Mannequin and the five Reference Mannequins.

    .venv/bin/python -m tools.shipped.build_reference [--refmodels DIR] [--out DIR] [--docs DIR] [--no-blend]
    .venv/bin/python -m tools.shipped.build_reference --check  # rebuild in memory, compare with the shipped files, docs

``--check`` passes when every shipped number is within CHECK_TOLERANCE of the rebuild and the docs
match it at their printed precision (a number may differ by one unit of its last printed digit,
where rounding puts it on either side): other CPUs' BLAS differ from this one's in the last bits,
which the build does not amplify (tests/tools/shipped/test_build_reference.py perturbs it to make sure).

Reads the body meshes of ``<repo>/../shared/refmodels`` (see its README) and writes
``reference_blends/base_mannequin.json`` and the five ``<name>.json`` Reference Mannequins, their
.blend twins, a Workbench line-up ``docs/images/reference_lineup.png`` and the Base Mannequin over
its body ``docs/images/base_mannequin_trace.png`` (with the bpy module), ``docs/topology.md`` and
``docs/reference_mannequins.md`` (with how much of its body each mannequin fills, tools/shipped/coverage.py).

Steps (paper, Sections 2.3.2-2.3.4):
1. Trace: every part of tools/shipped/reference_topology.py selects its vertices on the neutral reference body
   (regions and bones of its labels); the selections and fit settings are recorded on the Base
   Mannequin's parts (core/mannequin/traces.py), as Fit Ellipsoid records them in Blender.
2. Base Mannequin: the parts fitted over ``reference_female.obj`` (core/fitting/mannequin_fit.py), registered and
   made symmetric.
3. Reference Mannequins: the product's builder (core/fitting/reference_build.py, ``ellimann references
   build``) on the five bodies and Table 2.3, the Average RM the one the others' axes are labelled
   against.
4. Joints: each body's SMPL joints from its own rig (skeleton.json, core.mannequin.joints.joints_from_makehuman) go
through
   every step the pieces go through: mirrored with them, registered with them, and moved by the refinement as
   points fixed in their anchor parts (core.mannequin.joints.follow_pieces, in core/fitting/reference_build.py).
Deterministic: no randomness, fixed iteration counts and orders.
"""

import argparse
import dataclasses
import hashlib
import json
import pathlib
import re
import sys
import time
import zlib

import numpy as np

from ellimann_addon.core.constants import REFERENCE_MEASUREMENTS, SECTION_FRACTIONS
from ellimann_addon.core.files import atomic_write_text
from ellimann_addon.core.fitting.body_mesh import hidden_vertices, read_obj, vertex_normals
from ellimann_addon.core.fitting.mannequin_fit import FitConstants, fit_mannequin
from ellimann_addon.core.fitting.reference_build import (
    BuildSettings,
    build_reference_set,
    cleanliness_problems,
    display_name,
    relative_errors,
)
from ellimann_addon.core.geometry.ellipsoid import section_at_height
from ellimann_addon.core.geometry.frames import axis_agreement
from ellimann_addon.core.mannequin.clean import register_to_world, registration_offset, symmetrize
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.traces import PartTrace
from ellimann_addon.core.measure.tailor import section_heights
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.bodies import BODIES_FILE
from ellimann_addon.core.synthesis.body_space import SPACE_FILE
from ellimann_addon.core.synthesis.manifest import MANIFEST_FILE, legacy_manifest, read_manifest

from . import coverage
from . import reference_topology as rt
from .bodies import REFERENCE_BODY, RM_BODIES, body_measurements, load_labels, load_skeletons

REPO = pathlib.Path(__file__).resolve().parents[2]
DEFAULT_REFMODELS = REPO.parent / "shared" / "refmodels"
BASE_FILE = "base_mannequin"
REFERENCE_RM = "average"  # the RM whose axes the others are relabelled against
CHECK_TOLERANCE = 1e-6  # m (and for the rotations' entries): what --check lets a rebuild differ by
LINEUP_ORDER = ("small_chubby", "small_slim", "average", "tall_slim", "tall_chubby")  # the paper's Figure 2.9
DISPLAY_NAMES = {**{stem: display_name(stem) for stem in RM_BODIES}, BASE_FILE: "Base Mannequin"}
FILL_SPACING = FitConstants().fill_spacing


def trace_reference(reference_body, labels, specs=rt.SPECS):
    """{part name: PartTrace}: the vertices of every part of ``specs`` (default: the shipped 40,
    tools/shipped/reference_topology.py) on the reference body and its fit settings; the cavity walls (open mouth and
    eye sockets, bodies.hidden_vertices) are looked for in the head only: elsewhere every vertex is skin. Also returns
    the cavity mask (bool per vertex)."""
    vertices = reference_body.vertices
    height = vertices[:, 2].max() - vertices[:, 2].min()
    hidden = np.zeros(len(vertices), dtype=bool)
    if any(spec.cavities for spec in specs):
        head = np.nonzero(labels.region == "head")[0]
        normals = vertex_normals(vertices, reference_body.faces)
        hidden[head] = hidden_vertices(vertices, reference_body.faces, normals, head)
    traces = {}
    for spec, side in rt.expanded(specs):
        name = rt.part_name(spec, side)
        idx = rt.select_vertices(spec.select, side, vertices, labels, height)
        if len(idx) < 8:
            raise ValueError(f"'{name}' selects only {len(idx)} vertices: widen its selection")
        cavity = np.nonzero(hidden)[0] if spec.cavities and not spec.mitten else np.zeros(0, dtype=np.int64)
        traces[name] = PartTrace(
            reference_body.name, len(vertices), reference_body.edges_crc, idx, rt.fit_settings(spec), cavity
        )
    return traces, hidden


def trace_base(reference_body, traces, constants=None, joints=None, topology=None):
    """The Base Mannequin fitted over the reference body: symmetric, registered, each part's trace
    recording the axis its frame took from the points, ``joints`` (the body's, or None) moved with it.
    ``constants``: the fit's (core.fitting.mannequin_fit.FitConstants; default the female set's section heights);
    ``topology``: its parts (default: the shipped 40 of tools/shipped/reference_topology.py).
    Returns (base, body -> base translation)."""
    topology = topology or rt.topology()
    base, kept = fit_mannequin(
        reference_body, topology, traces, constants=constants, name=DISPLAY_NAMES[BASE_FILE], role="base"
    )
    base = symmetrize(base.copy(joints=joints))  # symmetric first: mirroring may move the lowest point
    shift = registration_offset(base)
    traces = {
        name: dataclasses.replace(trace, fit=dataclasses.replace(trace.fit, kept=kept[topology.index[name]]))
        for name, trace in traces.items()
    }
    return register_to_world(base).copy(traces=traces), shift


def build(refmodels=DEFAULT_REFMODELS, log=print, jitter=0.0):
    """Build BM and the five RMs. Returns (base, {name: rm}, report dict).

    ``jitter`` (m): every body vertex moved by a seeded uniform offset up to that much, to test that
    the build does not amplify rounding (tests/tools/shipped/test_build_reference.py).
    """
    started = time.perf_counter()
    labels = load_labels(refmodels)

    def load_body(name):
        body = read_obj(pathlib.Path(refmodels) / f"{name}.obj", up="z")
        if not jitter:
            return body
        rng = np.random.default_rng(zlib.crc32(name.encode()))
        return dataclasses.replace(body, vertices=body.vertices + rng.uniform(-jitter, jitter, body.vertices.shape))

    reference_body = load_body(REFERENCE_BODY)
    skeletons = load_skeletons(refmodels)
    traces, cavity = trace_reference(reference_body, labels)
    base, base_shift = trace_base(reference_body, traces, joints=skeletons[REFERENCE_BODY])
    log(f"base mannequin fitted ({len(base)} parts)")
    bodies = [dataclasses.replace(load_body(name), joints=skeletons[name]) for name in RM_BODIES]
    built_set = build_reference_set(
        base,
        bodies,
        REFERENCE_MEASUREMENTS,
        settings=BuildSettings(check_spacing=None),
        reference=REFERENCE_RM,
        progress=lambda fraction, text: log(f"{fraction:4.0%} {text}"),
    )
    built, base, rms = built_set.report, built_set.base, built_set.mannequins
    shifts = {BASE_FILE: base_shift, **built.shifts}
    fill = {}
    for name, m in [(BASE_FILE, base), *rms.items()]:
        body = reference_body if name == BASE_FILE else bodies[RM_BODIES.index(name)]
        fill[name] = coverage.report(m, body.vertices + shifts[name], body.faces, cavity)
    log("coverage measured")
    report = {
        "seconds": time.perf_counter() - started,
        "fill": fill,
        "shifts": shifts,
        "body_measurements": {body.name: body_measurements(body, labels) for body in [reference_body, *bodies]},
        "fitted_measurements": built.fitted,
        "factors": built.factors,
        "agreement": axis_agreement_table(rms),
        "reference_rm": REFERENCE_RM,
    }
    return base, rms, report


def axis_agreement_table(rms):
    """Per part, the smallest cosine between an axis and the same axis of the reference RM."""
    reference = rms[REFERENCE_RM]
    stacked = np.stack([axis_agreement(m.rotation, reference.rotation) for m in rms.values()])
    return dict(zip(reference.topology.names, stacked.min(axis=(0, 2)).tolist()))


def sections_crossed(mannequin):
    """{measurement: [part names cut by its section]} (all parts for Sh, girth parts for the girths)."""
    _, _, heights = section_heights(mannequin.rotation, mannequin.center, mannequin.semi_axes)
    girth = mannequin.topology.girth_mask
    out = {}
    for key in ("Sh", "Br", "Wa", "Hi"):
        _, _, hit = section_at_height(mannequin.rotation, mannequin.center, mannequin.semi_axes, heights[key])
        if key != "Sh":
            hit = hit & girth
        out[key] = [name for name, h in zip(mannequin.topology.names, hit) if h]
    return out


def shipped_manifest(refmodels):
    """The shipped set's reference_set.json (core.synthesis.manifest): Table 2.3, today's constants, the bodies."""
    bodies = {
        name: {
            "file": f"{name}.obj",
            "sha256": hashlib.sha256((pathlib.Path(refmodels) / f"{name}.obj").read_bytes()).hexdigest(),
        }
        for name in (REFERENCE_BODY, *RM_BODIES)
    }
    manifest = legacy_manifest()
    manifest.base = BASE_FILE
    manifest.bodies = BODIES_FILE  # the RMs' bodies, for the body skin (tools/shipped/add_bodies.py)
    manifest.body_space = (
        SPACE_FILE  # its bank and its six bodies, for the ridge body model (tools/shipped/add_body_space.py)
    )
    manifest.provenance = {
        "built_by": "python -m tools.shipped.build_reference",
        "bodies": "../shared/refmodels (Anny 0.6.2)",
        "traced_on": REFERENCE_BODY,
        "labelled_against": REFERENCE_RM,
        "files": bodies,
        "targets": "the paper's Table 2.3",
    }
    return manifest


def save_all(mannequins, out, manifest):
    """Write the JSON files and the manifest; returns the stems whose file is new or changed."""
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    changed = []
    for stem, mannequin in mannequins.items():
        path = out / f"{stem}.json"
        text = mannequin.to_json() + "\n"
        if not path.is_file() or path.read_text(encoding="utf-8") != text:
            mannequin.save(path)
            changed.append(stem)
    text = json.dumps(manifest.to_dict(), indent=1) + "\n"
    path = out / MANIFEST_FILE
    if not path.is_file() or path.read_text(encoding="utf-8") != text:
        atomic_write_text(path, text)
        changed.append(MANIFEST_FILE)
    return changed


def write_blends(stems, folder):
    """The .blend twins of ``folder``'s ``<stem>.json`` files, saved by the oldest supported Blender
    (tools/shipped/reference_blends.py: no Blender opens a newer one's file)."""
    from . import reference_blends

    if reference_blends.main(["--folder", str(folder), *stems]):
        raise SystemExit("the .blend twins could not be written")


def write_lineup(files, path):
    """Workbench render of mannequin JSON files side by side (tools/pictures/render.py). Needs the bpy module."""
    from ..pictures import render

    path.parent.mkdir(parents=True, exist_ok=True)
    render.main(["mannequins", *map(str, files), "--out", str(path)])


def write_trace(mannequin_file, body_file, shift, path):
    """Workbench render of a mannequin over the semi-transparent body it was traced from (moved by
    ``shift``, the mannequin's registration), front and side. Needs the bpy module."""
    from ..pictures import render

    path.parent.mkdir(parents=True, exist_ok=True)
    render.main(
        [
            "mannequins",
            str(mannequin_file),
            "--ghost",
            str(body_file),
            "--ghost-shift",
            *(f"{v:.9g}" for v in shift),
            "--side-too",
            "--out",
            str(path),
        ]
    )


def check_shipped(base, rms, folder, atol=CHECK_TOLERANCE):
    """Differences beyond ``atol`` between a fresh build and the shipped JSON files (empty list: none)."""
    folder = pathlib.Path(folder)
    problems = []
    for stem, fresh in [(BASE_FILE, base), *rms.items()]:
        shipped = Mannequin.load(folder / f"{stem}.json")
        if shipped.topology != fresh.topology:
            problems.append(f"{stem}: topology differs")
            continue
        if (shipped.joints is None) != (fresh.joints is None):
            problems.append(f"{stem}: joints {'missing' if shipped.joints is None else 'unexpected'}")
            continue
        for attr in ("rotation", "center", "semi_axes") + (("joints",) if fresh.joints is not None else ()):
            diff = float(np.abs(getattr(shipped, attr) - getattr(fresh, attr)).max())
            if diff > atol:
                problems.append(f"{stem}: {attr} differs by up to {diff:.3g}")
        if {k: t.to_dict() for k, t in (shipped.traces or {}).items()} != {
            k: t.to_dict() for k, t in (fresh.traces or {}).items()
        }:
            problems.append(f"{stem}: the recorded selections (traces) differ")
    return problems


_NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?")


def docs_differ(shipped, fresh):
    """Whether two generated docs differ beyond their printed precision: the same text around the
    numbers, each number printed with the same digits and off by at most one unit of the last."""
    a, b = _NUMBER.split(shipped), _NUMBER.split(fresh)
    if a != b:
        return True
    for x, y in zip(_NUMBER.findall(shipped), _NUMBER.findall(fresh)):
        decimals = len(x.partition(".")[2])
        if decimals != len(y.partition(".")[2]) or abs(float(x) - float(y)) > 1.5 * 10.0**-decimals:
            return True
    return False


def check(base, rms, docs, out, docs_folder, refmodels=DEFAULT_REFMODELS):
    """What --check reports: shipped JSON files, manifest and docs that differ from a build (empty: none)."""
    manifest = read_manifest(out)
    stale = manifest is None or manifest.to_dict() != shipped_manifest(refmodels).to_dict()
    return (
        check_shipped(base, rms, out)
        + [f"{MANIFEST_FILE} is not what the build writes"] * stale
        + [
            f"docs/{name} is not what the build writes"
            for name, text in docs.items()
            if not (docs_folder / name).is_file() or docs_differ((docs_folder / name).read_text(), text)
        ]
    )


# ---------------------------------------------------------------- docs


def _fmt(value, digits=2):
    return f"{value:.{digits}f}"


def _row(values, digits=2):
    return " | ".join(_fmt(values[key], digits) for key in MEASUREMENTS)


def generated_docs(base, rms, report):
    """{file name in docs/: text} of the docs the build writes."""
    return {"topology.md": topology_doc(base), "reference_mannequins.md": measurements_doc(base, rms, report)}


def topology_doc(base):
    lines = [
        "# ElliMann's reference topology",
        "",
        "<!-- generated by `python -m tools.shipped.build_reference`; "
        "edit tools/shipped/reference_topology.py, not this file -->",
        "",
        f"{len(base.topology)} ellipsoids, head to feet, arms and hands included. Names follow the paper "
        "(`<number>.<letter> <Label>[.L|.R]`); the numbers of the two parts the paper names keep the "
        "paper's (10.a Trapezius, 13.a Rectus Abdominalis). Two ellipsoids with the same number and side "
        "form a cushion (letters a and b). `.L` parts are on the body's left (+X), `.R` parts are their "
        "mirror images, central parts are symmetric about x = 0. The `Trapezius` pair is the registration "
        "landmark of `core/mannequin/clean.py`.",
        "",
    ]
    return "\n".join(lines + topology_tables(base, rt.SPECS)) + "\n"


def topology_tables(base, specs):
    """Markdown lines: what the columns mean, every part of ``base`` (traced by ``specs``) and the parts each
    section cuts."""
    crossed = sections_crossed(base)
    lines = [
        "- **girth**: takes part in the breast, waist and hip sections of m_T (arms and hands do not; the "
        "shoulder width is measured over every part).",
        "- **depends**: the measurements the part is interpolated on in synthesis (segmented IDW): head and "
        "neck on He; shoulders, arms and hands on He and Sh; bust and chest on He and Br; abdomen and "
        "lower back on He and Wa; pelvis, buttocks and legs on He and Hi.",
        "- **traced from**: the vertices of the reference body the part is fitted to (regions and bones of "
        "`refmodels/reference_female_regions.json`, heights `h` as fractions of the body's height, "
        "`x` lateral and `y` front(-)/back(+) bands in metres).",
        "",
        "- **fit**: how the part is fitted (`ellimann_addon/core/fitting/inscribed.py`): an ellipsoid inside the body "
        "surface "
        f"moved out by `depth` (default {rt.Spec.depth * 1e3:g} mm, so a part may reach that far outside the skin "
        "rather than leave a gap) and within the selection's box enlarged by `margin` of its half-size (default "
        f"{rt.Spec.margin:g}); vertices of total area `inside` of the nearby surface (default {rt.Spec.inside:g}) "
        "may lie inside it. Among such ellipsoids, each as large as the body lets it grow from its centre, the "
        "one that covers most of the body's volume within the box (sampled on a "
        f"{FILL_SPACING * 1e3:g} mm grid) is chosen: a part fills its region instead of settling where the body is "
        "thickest. The frame takes one axis from the vertices (*limb*: the line through the centroids of the "
        "two ends; *main*: the principal axis that stands most apart; *axis*: the direction given) and the rest "
        "from the world axes (on the Reference Mannequins: from the Base Mannequin's part); *fixed*: world axes. "
        "A part that *spans its selection* reaches from one end of it to the other along that axis. A girth "
        f"part keeps {FitConstants().section_clearance:g} of the height clear of the girth sections of the "
        "measurements it does not depend on, so each section cuts only parts that follow its measurement (table "
        "below).",
        "",
        "| part | side | cushion partner | region | girth | depends | traced from | fit |",
        "|---|---|---|---|---|---|---|---|",
    ]
    by_name = dict((rt.part_name(spec, side), spec) for spec, side in rt.expanded(specs))
    for part in base.topology:
        spec = by_name[part.name]
        lines.append(
            f"| {part.name} | {part.side} | {part.partner or '-'} | {part.region} | "
            f"{'yes' if part.girth else 'no'} | {', '.join(part.depends)} | {_describe(spec)} | "
            f"{_fit_notes(spec)} |"
        )
    lines += [
        "",
        "## Parts cut by each section of the Base Mannequin",
        "",
        "| measurement | height (fraction of He) | parts |",
        "|---|---|---|",
    ]
    for key, names in crossed.items():
        lines.append(f"| {key} | {SECTION_FRACTIONS[key]} | {', '.join(names)} |")
    return lines


def _describe(spec):
    select = spec.select
    items = []
    if select.regions:
        items.append("regions " + "/".join(select.regions))
    if select.bones:
        items.append("bones " + "/".join(f"{b}*" for b in select.bones))
    for axis in ("h", "x", "y"):
        lo, hi = getattr(select, axis)
        if lo > -1 or hi < 1:
            lo_text = "" if lo <= -1 else f"{lo:g} ≤ "
            hi_text = "" if hi >= 1 else f" ≤ {hi:g}"
            items.append(f"{lo_text}{axis}{hi_text}")
    if spec.inward is not None:
        items.append("surface patch extruded by ({}) m".format(", ".join(f"{v:g}" for v in spec.inward)))
    return "; ".join(items)


def _fit_notes(spec):
    defaults = rt.Spec(0, "a", "", "C", "", True, ("He",), rt.Select())
    items = [f"{spec.frame} frame" + (" ({})".format(", ".join(f"{v:g}" for v in spec.axis)) if spec.axis else "")]
    for attr, unit in (
        ("margin", ""),
        ("depth", " m"),
        ("inside", ""),
        ("clearance", ""),
        ("shared", ""),
        ("wall_spacing", " m"),
        ("outside_cost", ""),
    ):
        if getattr(spec, attr) is not None and getattr(spec, attr) != getattr(defaults, attr):
            items.append(f"{attr} {getattr(spec, attr):g}{unit}")
    if spec.span:
        items.append("spans its selection")
    if spec.mitten:
        items.append("inside the hull of its vertices (a mitten)")
    if spec.cavities:
        items.append("fills the mesh's open mouth and eye sockets")
    if spec.level is not None:
        items.append(f"centred at h = {SECTION_FRACTIONS[spec.level]:g}")
    return ", ".join(items)


def measurements_doc(base, rms, report):
    lines = [
        "# Reference Mannequins: Table 2.3 vs m_T",
        "",
        "<!-- generated by `python -m tools.shipped.build_reference`; do not edit -->",
        "",
        "m_T is `Mannequin.measure()` (closed form) of the shipped JSON files in `reference_blends/`. "
        "Each RM is the topology of `docs/topology.md` fitted inside its body from `refmodels/`, "
        "deformed by the exact-mode refinement of synthesis (`core.synthesis.refine`) until m_T meets "
        "Table 2.3, then cleaned together with the others "
        f"(registration, symmetry, axes relabelled against the {DISPLAY_NAMES[report['reference_rm']]} RM).",
        "",
        "| RM | | He | Sh | Br | Wa | Hi | max rel. error |",
        "|---|---|---|---|---|---|---|---|",
    ]
    lines += target_rows(rms, REFERENCE_MEASUREMENTS)
    lines += [
        "",
        "## How far each body and fit were from the table",
        "",
        "The body is the mesh in `refmodels/` (measured like m_T on the mesh, as its README says); the fit "
        "is the RM before the adjustment (ellipsoids fitted in the body, reaching at most a few mm out); the "
        "factors are those of the refinement (He: vertical stretch; Sh: shoulders widened, arms carried "
        "out; Br, Wa, Hi: girth parts scaled horizontally, blended with height around each section).",
        "",
        "| RM | | He | Sh | Br | Wa | Hi |",
        "|---|---|---|---|---|---|---|",
    ]
    lines += fit_rows(rms, report)
    body = report["body_measurements"][REFERENCE_BODY]
    measured = base.measure()
    lines += [
        "",
        "## Base Mannequin vs the reference body",
        "",
        "The Base Mannequin is traced, not adjusted: its m_T is that of the fitted ellipsoids.",
        "",
        "| | He | Sh | Br | Wa | Hi |",
        "|---|---|---|---|---|---|",
        "| reference body | " + _row(body) + " |",
        "| Base Mannequin m_T | " + _row(measured) + " |",
        "| relative difference | " + " | ".join(f"{measured[k] / body[k] - 1.0:+.1%}" for k in MEASUREMENTS) + " |",
        "",
        *fill_doc(report["fill"]),
        "## Consistency of axis labels",
        "",
        "Smallest cosine between an ellipsoid's axis and the same axis of the same ellipsoid in the "
        f"{DISPLAY_NAMES[report['reference_rm']]} RM, over the five RMs and three axes: "
        f"**{min(report['agreement'].values()):.4f}** (1 = identical). Every part, lowest first:",
        "",
        "| part | smallest agreement |",
        "|---|---|",
    ]
    for name, value in sorted(report["agreement"].items(), key=lambda item: item[1]):
        lines.append(f"| {name} | {value:.4f} |")
    return "\n".join(lines) + "\n"


def target_rows(rms, targets):
    """Markdown rows of the targets-vs-m_T table: each RM's targets, its m_T and its largest relative error."""
    lines = []
    for name, rm in rms.items():
        measured, target = rm.measure(), targets[name]
        worst = max(abs(e) for e in relative_errors(measured, target).values())
        lines.append(f"| {DISPLAY_NAMES[name]} | target | " + _row(target) + " | |")
        lines.append("| | m_T | " + _row(measured) + f" | {worst:.4%} |")
    return lines


def fit_rows(rms, report):
    """Markdown rows of the bodies-and-fits table: each RM's body, its fit before the refinement, the factors."""
    lines = []
    for name in rms:
        lines.append(f"| {DISPLAY_NAMES[name]} | body | " + _row(report["body_measurements"][name]) + " |")
        lines.append("| | fit | " + _row(report["fitted_measurements"][name]) + " |")
        lines.append("| | factor | " + _row(report["factors"][name], 4) + " |")
    return lines


def fill_doc(fill, links=coverage.CHAINS, depth=rt.Spec.depth, topology_doc="topology.md"):
    """Markdown lines: how each mannequin fills its body (tools/shipped/coverage.py), the gaps along the chains
    ``links``; ``depth`` (m): how far the topology's parts (``topology_doc``) may reach outside the skin."""
    spacing = coverage.GRID_SPACING * 1e3
    lines = [
        "## How much of its body each mannequin fills",
        "",
        "Measured by `tools/shipped/coverage.py` against the body each mannequin was traced from (moved by the same "
        f"registration), on a regular {spacing:g} mm grid: **coverage** is the share of the body's volume "
        "inside the union of the pieces, **excess** the share of the pieces' volume outside the body, "
        "**depth** how far (mm) a piece reaches outside the body surface at most, and which. *Ellipsoids*: "
        "the ellipsoid mannequin; *cushions*: every cushion pair replaced by its hull. The parts may reach "
        f"{depth * 1e3:g} mm outside the skin by design (`depth` in `docs/{topology_doc}`); the mitten over "
        "the spread fingers reaches further, between them. The points in the mesh's open mouth and eye sockets "
        "(no eyes or teeth), which the solid head fills, are not counted in the depth or the excess. The "
        "Reference Mannequins "
        "are measured after their adjustment to Table 2.3, which moves and scales parts off their bodies (girth "
        "parts widened or narrowed, the arms carried sideways with the shoulder width).",
        "",
        "| mannequin | coverage | excess | depth (mm) | cushions: coverage | excess | depth (mm) |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, metrics in fill.items():
        e, c = metrics["ellipsoids"], metrics["cushions"]
        lines.append(
            f"| {DISPLAY_NAMES[name]} | {e['coverage']:.1%} | {e['excess']:.1%} | {e['depth'] * 1e3:.1f} "
            f"({e['deepest']}) | {c['coverage']:.1%} | {c['excess']:.1%} | {c['depth'] * 1e3:.1f} "
            f"({c['deepest']}) |"
        )
    chains = list(links)
    lines += [
        "",
        "Largest gap (mm) between consecutive links of each chain (0: every link touches the next), "
        "ellipsoids / cushions. The chains, link by link (left side; the first link of a limb is where it "
        "hangs from the trunk): "
        + "; ".join(f"*{chain}*: " + " → ".join("/".join(link) for link in links[chain]) for chain in chains)
        + ".",
        "",
        "| mannequin | " + " | ".join(chains) + " |",
        "|---|" + "---|" * len(chains),
    ]
    for name, metrics in fill.items():
        cells = [
            f"{max(metrics['ellipsoids']['gaps'][chain]) * 1e3:.0f} / "
            f"{max(metrics['cushions']['gaps'][chain]) * 1e3:.0f}"
            for chain in chains
        ]
        lines.append(f"| {DISPLAY_NAMES[name]} | " + " | ".join(cells) + " |")
    return lines + [""]


def summary(base, rms):
    """One line per mannequin: clean or not, and the largest m_T error against Table 2.3."""
    lines = []
    for stem, m in [(BASE_FILE, base), *rms.items()]:
        text = f"{stem:15s} {'; '.join(cleanliness_problems(m)) or 'valid, right-handed, symmetric, registered'}"
        if stem in REFERENCE_MEASUREMENTS:
            errors = relative_errors(m.measure(), REFERENCE_MEASUREMENTS[stem])
            text += f", max m_T error vs Table 2.3 {max(abs(e) for e in errors.values()):.4%}"
        lines.append(text)
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.shipped.build_reference", description=__doc__.split("\n")[0])
    parser.add_argument(
        "--refmodels",
        type=pathlib.Path,
        default=DEFAULT_REFMODELS,
        help=f"folder of the reference bodies (default: {DEFAULT_REFMODELS})",
    )
    parser.add_argument(
        "--out",
        type=pathlib.Path,
        default=REPO / "reference_blends",
        help="where the mannequins go (default: reference_blends/)",
    )
    parser.add_argument("--docs", type=pathlib.Path, default=REPO / "docs", help="where the docs go (default: docs/)")
    parser.add_argument("--no-blend", action="store_true", help="skip the .blend files and the line-up (no bpy needed)")
    parser.add_argument(
        "--check", action="store_true", help="rebuild in memory and compare with the files in --out; write nothing"
    )
    args = parser.parse_args(argv)
    if not (args.refmodels / f"{REFERENCE_BODY}.obj").is_file():
        print(f"error: no {REFERENCE_BODY}.obj in {args.refmodels} (use --refmodels)", file=sys.stderr)
        return 2

    base, rms, report = build(args.refmodels)
    for line in summary(base, rms):
        print(line)
    print(f"smallest axis agreement with the {REFERENCE_RM} RM: {min(report['agreement'].values()):.4f}")
    for name, metrics in report["fill"].items():
        e, c = metrics["ellipsoids"], metrics["cushions"]
        print(
            f"{name:15s} fill: coverage {e['coverage']:.1%} (cushions {c['coverage']:.1%}), excess {e['excess']:.1%} "
            f"({c['excess']:.1%}), depth {e['depth'] * 1e3:.1f} mm at {e['deepest']} "
            f"({c['depth'] * 1e3:.1f} at {c['deepest']})"
        )
        print(
            " " * 16
            + "gaps (mm, ellipsoids / cushions): "
            + "; ".join(
                f"{chain} "
                + " ".join(f"{a * 1e3:.0f}/{b * 1e3:.0f}" for a, b in zip(e["gaps"][chain], c["gaps"][chain]))
                for chain in coverage.CHAINS
            )
        )
    print(f"built in {report['seconds']:.1f} s")
    docs = generated_docs(base, rms, report)
    if args.check:
        problems = check(base, rms, docs, args.out, args.docs, args.refmodels)
        print(
            "\n".join(problems)
            if problems
            else f"identical to the files in {args.out} and {args.docs} "
            f"(within {CHECK_TOLERANCE:g} m and the docs' printed precision)"
        )
        return 1 if problems else 0

    mannequins = {BASE_FILE: base, **rms}
    changed = save_all(mannequins, args.out, shipped_manifest(args.refmodels))
    from .add_bodies import set_bodies  # the set's bodies beside its RMs, as the manifest names them
    from .reference_sets import FEMALE

    set_bodies(FEMALE, list(RM_BODIES)).save(pathlib.Path(args.out) / BODIES_FILE)
    args.docs.mkdir(parents=True, exist_ok=True)
    for name, text in docs.items():
        atomic_write_text(args.docs / name, text)
    print(f"{len(changed)} of {len(mannequins)} JSON files changed in {args.out}; docs written to {args.docs}")
    if not args.no_blend:
        # .blend and .png files are not byte-reproducible: rewrite only what changed (or is missing)
        stale = {
            stem: m for stem, m in mannequins.items() if stem in changed or not (args.out / f"{stem}.blend").is_file()
        }
        if stale:
            write_blends(sorted(stale), args.out)
        print(f"{len(stale)} .blend files written")
        lineup = args.docs / "images" / "reference_lineup.png"
        if set(changed) & set(RM_BODIES) or not lineup.is_file():
            write_lineup([args.out / f"{stem}.json" for stem in LINEUP_ORDER], lineup)
        trace = args.docs / "images" / "base_mannequin_trace.png"
        if BASE_FILE in changed or not trace.is_file():
            write_trace(
                args.out / f"{BASE_FILE}.json",
                args.refmodels / f"{REFERENCE_BODY}.obj",
                report["shifts"][BASE_FILE],
                trace,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
