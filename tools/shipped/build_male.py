"""Build the male reference set, reference_blends/male/, with the product's reference-set builder.

    .venv/bin/python -m tools.shipped.build_male [--out DIR] [--docs DIR] [--no-blend]
    .venv/bin/python -m tools.shipped.build_male --check     # rebuild in memory, compare with the shipped files

1. Base Mannequin: the parts of the shipped female Base Mannequin, traced on the same vertices (its recorded
   selections: every body shares one mesh topology and vertex order), fitted over ``reference_male.obj``
   at the male section heights (tools/shipped/reference_sets.py: the parts keep clear of them and centre on
   them), made symmetric and registered: it records the male set and heights.
2. Reference Mannequins: core.fitting.reference_build.build_reference_set (what ``ellimann references build``
   runs) on the five male bodies of ``../shared/refmodels_male`` and their README's targets, at the base's
   section heights; written with core.synthesis.manifest.write_reference_set (the RMs, the base, the
   manifest), then their .blend twins (saved by Blender 4.2), the line-up, the Base Mannequin over its body
   and ``docs/reference_mannequins_male.md``.
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

from . import build_reference as br
from . import coverage
from .add_bodies import shipped_body_labels
from .bodies import RM_BODIES, body_measurements, load_labels, load_skeletons, read_bodies
from .reference_sets import FEMALE, MALE, TRACING_FOLDER

DOCS_NAME = MALE.docs_name
TRACE_PICTURE = "base_mannequin_trace_male.png"
LANDMARKS = {"reference_set": MALE.name, "section_fractions": MALE.fractions}
# the set's section heights, ranges (the targets' min-max) and the female set's plausibility limits (they bound
# what a body can be, not a population) go into its manifest with the build; where it came from:
PROVENANCE = {
    "built_by": "python -m tools.shipped.build_male (core.fitting.reference_build)",
    "bodies": "../shared/refmodels_male (Anny 0.6.2, Apache-2.0, on MakeHuman's CC0 assets)",
    "traced_on": f"{FEMALE.reference_body} (the female base's selections; one vertex order for every body)",
    "base_fitted_on": MALE.reference_body,
    "targets": "../shared/refmodels_male/README.md",
}


def build(log=print):
    """The male set (a core BuiltReferenceSet: the Base Mannequin, five RMs, the manifest) and a report dict as
    tools.shipped.build_reference's."""
    started = time.perf_counter()
    traced = Mannequin.load(FEMALE.out / f"{br.BASE_FILE}.json")  # its traces: the selections
    constants = FitConstants(section_fractions=dict(MALE.fractions))
    reference_body = read_obj(MALE.refmodels / f"{MALE.reference_body}.obj", up="z")
    skeletons = load_skeletons(MALE.refmodels)  # the male bodies' own joints, as the female set's
    base, base_shift = br.trace_base(reference_body, traced.traces, constants, joints=skeletons[MALE.reference_body])
    base = base.copy(**LANDMARKS)
    log(f"male base mannequin fitted ({len(base)} parts)")
    bodies = list(read_bodies(MALE.refmodels, RM_BODIES).values())
    built_set = build_reference_set(
        base,
        bodies,
        MALE.targets,
        reference=br.REFERENCE_RM,
        settings=BuildSettings(fit=constants, check_spacing=None),
        progress=lambda fraction, text: log(f"{fraction:4.0%} {text}"),
        name=MALE.name,
        sex=MALE.sex,
        base_stem=br.BASE_FILE,
        body_labels=shipped_body_labels(),  # the bodies kept with the set (bodies.npz, tools/shipped/add_bodies.py)
        provenance=PROVENANCE,
    )
    built_set.manifest.body_space = SPACE_FILE  # the set's bank, made by tools.add_body_space
    built, base, rms = built_set.report, built_set.base, built_set.mannequins
    cavity = np.zeros(len(reference_body.vertices), dtype=bool)  # the open mouth and eye sockets, as traced
    for trace in traced.traces.values():
        cavity[trace.cavity] = True
    shifts = {br.BASE_FILE: base_shift, **built.shifts}
    fill = {}
    for name, m in [(br.BASE_FILE, base), *rms.items()]:
        body = reference_body if name == br.BASE_FILE else bodies[RM_BODIES.index(name)]
        fill[name] = coverage.report(m, body.vertices + shifts[name], body.faces, cavity)
    log("coverage measured")
    labels = load_labels(TRACING_FOLDER)
    report = {
        "seconds": time.perf_counter() - started,
        "fill": fill,
        "shifts": shifts,
        "body_measurements": {
            body.name: body_measurements(body, labels, MALE.fractions) for body in [reference_body, *bodies]
        },
        "fitted_measurements": built.fitted,
        "factors": built.factors,
        "agreement": br.axis_agreement_table(rms),
        "reference_rm": br.REFERENCE_RM,
    }
    return built_set, report


def report_doc(base, rms, report):
    """docs/reference_mannequins_male.md: targets vs m_T, bodies and fits, the base, coverage and gaps."""
    fractions = ", ".join(f"{key} {value:g}" for key, value in MALE.fractions.items())
    lines = [
        "# Male Reference Mannequins: targets vs m_T",
        "",
        "<!-- generated by `python -m tools.shipped.build_male`; do not edit -->",
        "",
        "![The five male Reference Mannequins: Small Chubby, Small Slim, Average, Tall Slim, Tall Chubby]"
        "(images/reference_lineup_male.png)",
        "",
        "m_T is `Mannequin.measure()` (closed form) of the shipped JSON files in `reference_blends/male/`, at the "
        f"male section heights ({fractions} of He; `docs/synthesis.md` says why). The Base Mannequin is the "
        "topology of `docs/topology.md` traced on the same vertices as the female one (one mesh topology for every "
        "body) and fitted over `refmodels_male/reference_male.obj`; each RM is built from it by the product's "
        "reference-set builder (`core.fitting.reference_build`, `ellimann references build`): fitted inside its "
        "body from "
        "`refmodels_male/`, deformed by the exact-mode refinement until m_T meets the targets of "
        "`refmodels_male/README.md`, then cleaned together with the others (registration, symmetry, axes "
        f"relabelled against the {br.DISPLAY_NAMES[report['reference_rm']]} RM).",
        "",
        "| RM | | He | Sh | Br | Wa | Hi | max rel. error |",
        "|---|---|---|---|---|---|---|---|",
    ]
    lines += br.target_rows(rms, MALE.targets)
    lines += [
        "",
        "## How far each body and fit were from the targets",
        "",
        "The body is the mesh in `refmodels_male/` (measured like m_T on the mesh, at the male heights, as its "
        "README says); the fit is the RM before the refinement; the factors are the refinement's.",
        "",
        "| RM | | He | Sh | Br | Wa | Hi |",
        "|---|---|---|---|---|---|---|",
    ]
    lines += br.fit_rows(rms, report)
    body, measured = report["body_measurements"][MALE.reference_body], base.measure()
    lines += [
        "",
        "## Base Mannequin vs the neutral male body",
        "",
        "![The male Base Mannequin over the semi-transparent neutral male body, front and side]"
        f"(images/{TRACE_PICTURE})",
        "",
        "| | He | Sh | Br | Wa | Hi |",
        "|---|---|---|---|---|---|",
        "| reference body | " + br._row(body) + " |",
        "| Base Mannequin m_T | " + br._row(measured) + " |",
        "| relative difference | " + " | ".join(f"{measured[k] / body[k] - 1.0:+.1%}" for k in MEASUREMENTS) + " |",
        "",
        *br.fill_doc(report["fill"]),
        "Smallest cosine between an axis and the same axis in the "
        f"{br.DISPLAY_NAMES[report['reference_rm']]} RM, over the five RMs: "
        f"**{min(report['agreement'].values()):.4f}**.",
        "",
    ]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.shipped.build_male", description=__doc__.split("\n")[0])
    parser.add_argument(
        "--out", type=pathlib.Path, default=MALE.out, help="where the set goes (default: reference_blends/male/)"
    )
    parser.add_argument("--docs", type=pathlib.Path, default=br.REPO / "docs", help="where the docs go")
    parser.add_argument("--no-blend", action="store_true", help="skip the .blend files and pictures (no bpy needed)")
    parser.add_argument("--check", action="store_true", help="rebuild in memory and compare with --out; write nothing")
    args = parser.parse_args(argv)
    built, report = build()
    base, rms = built.base, built.mannequins
    for name, metrics in report["fill"].items():
        e, c = metrics["ellipsoids"], metrics["cushions"]
        print(
            f"{name:15s} coverage {e['coverage']:.1%} (cushions {c['coverage']:.1%}), excess {e['excess']:.1%} "
            f"({c['excess']:.1%}), depth {e['depth'] * 1e3:.1f} mm at {e['deepest']}"
        )
    for name, rm in rms.items():
        worst = max(abs(e) for e in relative_errors(rm.measure(), MALE.targets[name]).values())
        print(f"{name:15s} max m_T error vs its targets {worst:.4%}")
    print(f"built in {report['seconds']:.1f} s")
    doc = report_doc(base, rms, report)
    if args.check:
        problems = br.check_shipped(base, rms, args.out)
        shipped = args.docs / DOCS_NAME
        if not shipped.is_file() or br.docs_differ(shipped.read_text(encoding="utf-8"), doc):
            problems.append(f"docs/{DOCS_NAME} is not what the build writes")
        print("\n".join(problems) if problems else f"identical to the files in {args.out}")
        return 1 if problems else 0
    mannequins = {br.BASE_FILE: base, **rms}
    changed = [
        stem
        for stem, m in mannequins.items()
        if not (args.out / f"{stem}.json").is_file()
        or (args.out / f"{stem}.json").read_text(encoding="utf-8") != m.to_json() + "\n"
    ]
    built.write(args.out)
    atomic_write_text(args.docs / DOCS_NAME, doc)
    print(f"{len(changed)} of {len(mannequins)} JSON files changed in {args.out}; docs/{DOCS_NAME} written")
    if not args.no_blend:
        stale = sorted(stem for stem in mannequins if stem in changed or not (args.out / f"{stem}.blend").is_file())
        if stale:
            br.write_blends(stale, args.out)
        lineup = args.docs / "images" / MALE.lineup_name
        if set(changed) & set(RM_BODIES) or not lineup.is_file():
            br.write_lineup([args.out / f"{stem}.json" for stem in br.LINEUP_ORDER], lineup)
        trace = args.docs / "images" / TRACE_PICTURE
        if br.BASE_FILE in changed or not trace.is_file():
            br.write_trace(
                args.out / f"{br.BASE_FILE}.json",
                MALE.refmodels / f"{MALE.reference_body}.obj",
                report["shifts"][br.BASE_FILE],
                trace,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
