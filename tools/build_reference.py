"""Build ElliMann's reference data: the Base Mannequin and the five Reference Mannequins.

    .venv/bin/python -m tools.build_reference [--refmodels DIR] [--out DIR] [--docs DIR] [--no-blend]
    .venv/bin/python -m tools.build_reference --check     # rebuild in memory, compare with the shipped files

Reads the body meshes of ``<repo>/../shared/refmodels`` (see its README) and writes
``reference_blends/base_mannequin.json`` and the five ``<name>.json`` Reference Mannequins, their
.blend twins and a Workbench line-up ``docs/images/reference_lineup.png`` (both with the bpy module),
``docs/topology.md`` and ``docs/reference_mannequins.md``.

Steps (paper, Sections 2.3.2-2.3.4):
1. Trace: every part of tools/reference_topology.py is fitted to its vertices on a body
   (tools/fitting.py). The selections are made once on the neutral reference body; all bodies share
   its vertex order, so the same vertices trace the same part on each body.
2. Base Mannequin: the parts fitted over ``reference_female.obj``, registered and made symmetric.
3. Reference Mannequins: the parts fitted over each of the five bodies (axes labelled against the
   Base Mannequin's), registered and made symmetric, then deformed by synthesis' exact-mode
   refinement (core.synthesis.refine: rotations kept, symmetric) until m_T meets
   Table 2.3 within ADJUST_TOLERANCE; then the five are cleaned together (core.clean: registration,
   symmetry, axis relabelling against the Average RM) and checked against Table 2.3 within
   ACCEPT_TOLERANCE again.
Deterministic: no randomness, fixed iteration counts and orders.
"""

import argparse
import pathlib
import sys
import time
from dataclasses import dataclass

import numpy as np

from ellimann_addon.core.clean import asymmetry, clean, landmark_indices, register, relabel, symmetrize
from ellimann_addon.core.constants import MEASUREMENTS, REFERENCE_MEASUREMENTS, SECTION_FRACTIONS
from ellimann_addon.core.ellipsoid import section_at_height
from ellimann_addon.core.files import atomic_write_text
from ellimann_addon.core.frames import axis_agreement, is_rotation
from ellimann_addon.core.mannequin import Mannequin, Topology
from ellimann_addon.core.measure import as_dict, section_heights
from ellimann_addon.core.synthesis import refine

from . import reference_topology as rt
from .bodies import REFERENCE_BODY, RM_BODIES, body_measurements, load_body, load_labels, vertex_areas
from .fitting import inscribed_ellipsoid, moments_ellipsoid

REPO = pathlib.Path(__file__).resolve().parents[1]
DEFAULT_REFMODELS = REPO.parent / "shared" / "refmodels"
BASE_FILE = "base_mannequin"
REFERENCE_RM = "average"  # the RM whose axes the others are relabelled against
ADJUST_TOLERANCE = 1e-5  # relative m_T error the adjustment aims at
ADJUST_ITERATIONS = 40
ACCEPT_TOLERANCE = 5e-3  # what every shipped RM must meet (issue: 0.5% of Table 2.3)
LINEUP_ORDER = ("small_chubby", "small_slim", "average", "tall_slim", "tall_chubby")  # the paper's Figure 2.9
DISPLAY_NAMES = {"small_slim": "Small Slim", "tall_slim": "Tall Slim", "small_chubby": "Small Chubby",
                 "tall_chubby": "Tall Chubby", "average": "Average", BASE_FILE: "Base Mannequin"}


@dataclass(frozen=True)
class Tracing:
    """Which vertices trace each part (topology order): its selection, and the vertices it must stay inside.

    Chosen once on the reference body; every body shares its vertex order.
    """

    topology: Topology
    selected: list
    obstacles: list

    @classmethod
    def on(cls, reference_body, labels):
        vertices = reference_body.vertices
        height = vertices[:, 2].max() - vertices[:, 2].min()
        selected, obstacles = [], []
        for spec, side in rt.expanded():
            idx = rt.select_vertices(spec.select, side, vertices, labels, height)
            if len(idx) < 8:
                raise ValueError(f"'{rt.part_name(spec, side)}' selects only {len(idx)} vertices: widen its selection")
            selected.append(idx)
            obstacles.append(rt.obstacle_vertices(spec, side, labels))
        return cls(rt.topology(), selected, obstacles)


def fit_mannequin(body, tracing, reference=None, kept=None, **fields):
    """Fit every part over ``body``. Returns (mannequin, kept axis index per part).

    Without ``reference`` the frames take their roll from the world axes (the Base Mannequin);
    with it (a mannequin of the same topology, and the ``kept`` axes of its fit) each part keeps
    the axis closest to the reference part's kept axis and the reference's roll about it.
    ``fields``: name, role, measurements of the mannequin.
    """
    areas = vertex_areas(body.vertices, body.faces)
    n = len(tracing.topology)
    rotation, center, semi_axes = np.zeros((n, 3, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    kept_out = []
    for i, ((spec, _), idx, walls) in enumerate(zip(rt.expanded(), tracing.selected, tracing.obstacles)):
        points, weights = body.vertices[idx], areas[idx]
        if spec.inward is not None:
            points = np.concatenate([points, points + np.asarray(spec.inward)])
            weights = np.concatenate([weights, weights])
        ref_rotation = np.eye(3) if reference is None else reference.rotation[i]
        match = None if reference is None or kept[i] is None else reference.rotation[i][:, kept[i]]
        bottom, height = body.vertices[:, 2].min(), np.ptp(body.vertices[:, 2])
        floor = -np.inf if spec.floor is None else bottom + spec.floor * height
        level = None if spec.level is None else bottom + spec.level * height
        if spec.mode == "moments":
            fit = moments_ellipsoid(points, weights, ref_rotation, spec.frame, match)
        else:
            fit = inscribed_ellipsoid(points, weights, body.vertices[walls], areas[walls], ref_rotation,
                                      margin=spec.margin, inside_fraction=spec.inside, slack=spec.slack,
                                      frame=spec.frame, match=match, floor=floor, level=level)
        rotation[i], center[i], semi_axes[i], k = fit
        kept_out.append(k)
    return Mannequin(tracing.topology, rotation, center, semi_axes, **fields).check(), kept_out


def build(refmodels=DEFAULT_REFMODELS, log=print):
    """Build BM and the five RMs. Returns (base, {name: rm}, report dict)."""
    started = time.perf_counter()
    labels = load_labels(refmodels)
    reference_body = load_body(refmodels, REFERENCE_BODY)
    tracing = Tracing.on(reference_body, labels)

    base, kept = fit_mannequin(reference_body, tracing, name=DISPLAY_NAMES[BASE_FILE], role="base")
    # the right side is fitted too, as a check: mirror-image selections give near-mirror-image parts
    # (the optimisation can settle a few mm apart); cleaning keeps the left side
    log(f"base mannequin fitted ({len(base)} parts; asymmetry before mirroring {asymmetry(base):.1e} m)")
    base = register(symmetrize(base))  # symmetric first: mirroring may move the lowest point

    bodies, raw, adjusted, factors = {}, {}, [], {}
    for name in RM_BODIES:
        bodies[name] = load_body(refmodels, name)
        targets = REFERENCE_MEASUREMENTS[name]
        fitted, _ = fit_mannequin(bodies[name], tracing, base, kept, name=DISPLAY_NAMES[name], role="reference",
                                  measurements=dict(targets))
        raw[name] = register(symmetrize(fitted))
        adjusted.append(adjust(raw[name], targets))
        factors[name] = adjusted[-1].factors
        log(f"{name}: fitted and adjusted")

    cleaned = clean([a.mannequin for a in adjusted], reference_index=RM_BODIES.index(REFERENCE_RM))
    rms = dict(zip(RM_BODIES, cleaned))
    base = relabel(base, rms[REFERENCE_RM])
    for name, rm in rms.items():
        errors = relative_errors(rm.measure(), REFERENCE_MEASUREMENTS[name])
        worst = max(errors, key=lambda key: abs(errors[key]))
        if abs(errors[worst]) > ACCEPT_TOLERANCE:
            raise RuntimeError(f"{name}: after cleaning m_T {worst} is off Table 2.3 by {errors[worst]:.3%}")
    for name, m in [(BASE_FILE, base), *rms.items()]:
        problems = cleanliness_problems(m.check())
        if problems:
            raise RuntimeError(f"{name}: {'; '.join(problems)}")

    report = {
        "seconds": time.perf_counter() - started,
        "body_measurements": {name: body_measurements(body, labels)
                              for name, body in [(REFERENCE_BODY, reference_body), *bodies.items()]},
        "fitted_measurements": {name: m.measure() for name, m in raw.items()},
        "factors": factors,
        "agreement": axis_agreement_table(rms),
        "reference_rm": REFERENCE_RM,
    }
    return base, rms, report


@dataclass(frozen=True)
class Adjusted:
    mannequin: Mannequin
    factors: dict  # the stretch of each measurement's control (1 = unchanged)


def adjust(mannequin, targets):
    """``mannequin`` deformed until m_T meets ``targets`` (cm): synthesis' exact-mode refinement.

    Rotations are kept and the deformation is symmetric about x = 0 (core.synthesis.refine).
    """
    wanted = np.array([[targets[key] for key in MEASUREMENTS]])
    result = refine(mannequin.topology, mannequin.rotation[None], mannequin.center[None],
                    mannequin.semi_axes[None], wanted, tolerance=ADJUST_TOLERANCE,
                    max_iterations=ADJUST_ITERATIONS)
    if not result.converged[0]:
        raise RuntimeError(f"{mannequin.name}: the adjustment did not reach {targets} (m_T "
                           f"{as_dict(result.measured[0])}, factors {result.factors[0].round(4).tolist()})")
    adjusted = mannequin.copy(center=result.center[0], semi_axes=result.semi_axes[0])
    return Adjusted(adjusted, as_dict(result.factors[0]))


def cleanliness_problems(mannequin, tol=1e-9):
    """What keeps a mannequin from being clean: left-handed frames, asymmetry, not registered."""
    problems = []
    if not np.all(is_rotation(mannequin.rotation, tol)):
        problems.append("a frame is not a rotation")
    if asymmetry(mannequin) > tol:
        problems.append(f"asymmetric by {asymmetry(mannequin):.2g} m")
    floor = float(section_heights(mannequin.rotation, mannequin.center, mannequin.semi_axes)[0])
    if abs(floor) > tol:
        problems.append(f"lowest point at z = {floor:.2g} m")
    landmark = mannequin.center[landmark_indices(mannequin.topology)].mean(axis=0)
    if np.any(np.abs(landmark[:2]) > tol):
        problems.append(f"trapezius centroid at x, y = {landmark[0]:.2g}, {landmark[1]:.2g} m")
    return problems


def relative_errors(measured, targets):
    return {key: measured[key] / targets[key] - 1.0 for key in MEASUREMENTS}


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


def save_all(mannequins, out):
    """Write the JSON files; returns the stems whose file is new or changed."""
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    changed = []
    for stem, mannequin in mannequins.items():
        path = out / f"{stem}.json"
        text = mannequin.to_json() + "\n"
        if not path.is_file() or path.read_text(encoding="utf-8") != text:
            mannequin.save(path)
            changed.append(stem)
    return changed


def write_blends(mannequins, folder):
    """One .blend per mannequin (a collection of ellipsoid objects), through the add-on's converter.

    ``mannequins`` maps file stems to mannequins. Needs the bpy module.
    """
    import bpy

    import ellimann_addon
    from ellimann_addon.blender import convert

    folder = pathlib.Path(folder)
    ellimann_addon.register()
    try:
        for stem, mannequin in mannequins.items():
            bpy.ops.wm.read_homefile(use_empty=True)
            convert.mannequin_to_collection(mannequin, name=mannequin.name)
            bpy.ops.wm.save_as_mainfile(filepath=str(folder / f"{stem}.blend"), compress=True)
    finally:
        ellimann_addon.unregister()


def write_lineup(files, path):
    """Workbench render of mannequin JSON files side by side (tools/render.py). Needs the bpy module."""
    from . import render

    path.parent.mkdir(parents=True, exist_ok=True)
    render.main(["mannequins", *map(str, files), "--out", str(path)])


def check_shipped(base, rms, folder, atol=1e-9):
    """Differences between a fresh build and the shipped JSON files (empty list: identical)."""
    folder = pathlib.Path(folder)
    problems = []
    for stem, fresh in [(BASE_FILE, base), *rms.items()]:
        shipped = Mannequin.load(folder / f"{stem}.json")
        if shipped.topology != fresh.topology:
            problems.append(f"{stem}: topology differs")
            continue
        for attr in ("rotation", "center", "semi_axes"):
            diff = float(np.abs(getattr(shipped, attr) - getattr(fresh, attr)).max())
            if diff > atol:
                problems.append(f"{stem}: {attr} differs by up to {diff:.3g}")
    return problems


# ---------------------------------------------------------------- docs


def _fmt(value, digits=2):
    return f"{value:.{digits}f}"


def _row(values, digits=2):
    return " | ".join(_fmt(values[key], digits) for key in MEASUREMENTS)


def topology_doc(base):
    crossed = sections_crossed(base)
    lines = [
        "# ElliMann's reference topology",
        "",
        "<!-- generated by `python -m tools.build_reference`; edit tools/reference_topology.py, not this file -->",
        "",
        f"{len(base.topology)} ellipsoids, head to feet, arms and hands included. Names follow the paper "
        "(`<number>.<letter> <Label>[.L|.R]`); the numbers of the two parts the paper names keep the "
        "paper's (10.a Trapezius, 13.a Rectus Abdominalis). Two ellipsoids with the same number and side "
        "form a cushion (letters a and b). `.L` parts are on the body's left (+X), `.R` parts are their "
        "mirror images, central parts are symmetric about x = 0. The `Trapezius` pair is the registration "
        "landmark of `core/clean.py`.",
        "",
        "- **girth**: takes part in the breast, waist and hip sections of m_T (arms and hands do not; the "
        "shoulder width is measured over every part).",
        "- **depends**: the measurements the part is interpolated on in synthesis (segmented IDW): head and "
        "neck on He; shoulders, arms and hands on He and Sh; bust and chest on He and Br; abdomen and "
        "lower back on He and Wa; pelvis, buttocks and legs on He and Hi.",
        "- **traced from**: the vertices of the reference body the part is fitted to (regions and bones of "
        "`refmodels/reference_female_regions.json`, heights `h` as fractions of the body's height, "
        "`x` lateral and `y` front(-)/back(+) bands in metres).",
        "",
        "- **fit**: how the part is fitted (`tools/fitting.py`): the largest ellipsoid, by volume, inside "
        "the body surface and within the selection's box enlarged by `margin` of its half-size (default "
        f"{rt.Spec.margin:g}); a body vertex may lie inside it down to `slack` of its radius (default "
        f"{rt.Spec.slack:g}) and vertices of total area `inside` of the nearby surface (default "
        f"{rt.Spec.inside:g}) deeper. The frame takes one axis from the vertices (*limb*: the line through "
        "the centroids of the two ends; *main*: the principal axis that stands most apart) and the rest from "
        "the world axes (on the Reference Mannequins: from the Base Mannequin's part); *fixed*: world axes. "
        "A *moments* fit is the envelope of the vertices (for spread fingers, which no inscribed ellipsoid fills).",
        "",
        "| part | side | cushion partner | region | girth | depends | traced from | fit |",
        "|---|---|---|---|---|---|---|---|",
    ]
    specs = dict((rt.part_name(spec, side), spec) for spec, side in rt.expanded())
    for part in base.topology:
        spec = specs[part.name]
        lines.append(f"| {part.name} | {part.side} | {part.partner or '-'} | {part.region} | "
                     f"{'yes' if part.girth else 'no'} | {', '.join(part.depends)} | {_describe(spec)} | "
                     f"{_fit_notes(spec)} |")
    lines += ["", "## Parts cut by each section of the Base Mannequin", "",
              "| measurement | height (fraction of He) | parts |", "|---|---|---|"]
    for key, names in crossed.items():
        lines.append(f"| {key} | {SECTION_FRACTIONS[key]} | {', '.join(names)} |")
    return "\n".join(lines) + "\n"


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
    items = [f"{spec.frame} frame"]
    if spec.mode != defaults.mode:
        items.append(f"{spec.mode} fit")
    for attr in ("margin", "slack", "inside"):
        if getattr(spec, attr) != getattr(defaults, attr):
            items.append(f"{attr} {getattr(spec, attr):g}")
    if spec.obstacles is not None:
        items.append("kept inside the " + "/".join(spec.obstacles) + " surface only")
    if spec.floor is not None:
        items.append(f"kept above h = {spec.floor:g}")
    if spec.level is not None:
        items.append(f"centred at h = {spec.level:g}")
    return ", ".join(items)


def measurements_doc(base, rms, report):
    lines = [
        "# Reference Mannequins: Table 2.3 vs m_T",
        "",
        "<!-- generated by `python -m tools.build_reference`; do not edit -->",
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
    for name, rm in rms.items():
        target = REFERENCE_MEASUREMENTS[name]
        measured = rm.measure()
        errors = relative_errors(measured, target)
        worst = max(abs(e) for e in errors.values())
        lines.append(f"| {DISPLAY_NAMES[name]} | target | " + _row(target) + " | |")
        lines.append("| | m_T | " + _row(measured) + f" | {worst:.4%} |")
    lines += [
        "",
        "## How far each body and fit were from the table",
        "",
        "The body is the mesh in `refmodels/` (measured like m_T on the mesh, as its README says); the fit "
        "is the RM before the adjustment (inscribed ellipsoids, so a little smaller than the body); the "
        "factors are those of the refinement (He: vertical stretch; Sh: shoulders widened, arms carried "
        "out; Br, Wa, Hi: girth parts scaled horizontally, blended with height around each section).",
        "",
        "| RM | | He | Sh | Br | Wa | Hi |",
        "|---|---|---|---|---|---|---|",
    ]
    for name in rms:
        body = report["body_measurements"][name]
        fitted = report["fitted_measurements"][name]
        factors = report["factors"][name]
        lines.append(f"| {DISPLAY_NAMES[name]} | body | " + _row(body) + " |")
        lines.append("| | fit | " + _row(fitted) + " |")
        lines.append("| | factor | " + _row(factors, 4) + " |")
    body = report["body_measurements"][REFERENCE_BODY]
    measured = base.measure()
    lines += [
        "",
        "## Base Mannequin vs the reference body",
        "",
        "The Base Mannequin is traced, not adjusted: its m_T is that of inscribed ellipsoids.",
        "",
        "| | He | Sh | Br | Wa | Hi |",
        "|---|---|---|---|---|---|",
        "| reference body | " + _row(body) + " |",
        "| Base Mannequin m_T | " + _row(measured) + " |",
        "| relative difference | " + " | ".join(f"{measured[k] / body[k] - 1.0:+.1%}" for k in MEASUREMENTS) + " |",
        "",
        "## Consistency of axis labels",
        "",
        "Smallest cosine between an ellipsoid's axis and the same axis of the same ellipsoid in the "
        f"{DISPLAY_NAMES[report['reference_rm']]} RM, over the five RMs and three axes: "
        f"**{min(report['agreement'].values()):.4f}** (1 = identical). The five lowest parts:",
        "",
        "| part | smallest agreement |",
        "|---|---|",
    ]
    for name, value in sorted(report["agreement"].items(), key=lambda item: item[1])[:5]:
        lines.append(f"| {name} | {value:.4f} |")
    return "\n".join(lines) + "\n"


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
    parser = argparse.ArgumentParser(prog="python -m tools.build_reference", description=__doc__.split("\n")[0])
    parser.add_argument("--refmodels", type=pathlib.Path, default=DEFAULT_REFMODELS,
                        help=f"folder of the reference bodies (default: {DEFAULT_REFMODELS})")
    parser.add_argument("--out", type=pathlib.Path, default=REPO / "reference_blends",
                        help="where the mannequins go (default: reference_blends/)")
    parser.add_argument("--docs", type=pathlib.Path, default=REPO / "docs", help="where the docs go (default: docs/)")
    parser.add_argument("--no-blend", action="store_true", help="skip the .blend files and the line-up (no bpy needed)")
    parser.add_argument("--check", action="store_true",
                        help="rebuild in memory and compare with the files in --out; write nothing")
    args = parser.parse_args(argv)
    if not (args.refmodels / f"{REFERENCE_BODY}.obj").is_file():
        print(f"error: no {REFERENCE_BODY}.obj in {args.refmodels} (use --refmodels)", file=sys.stderr)
        return 2

    base, rms, report = build(args.refmodels)
    for line in summary(base, rms):
        print(line)
    print(f"smallest axis agreement with the {REFERENCE_RM} RM: {min(report['agreement'].values()):.4f}")
    print(f"built in {report['seconds']:.1f} s")
    if args.check:
        problems = check_shipped(base, rms, args.out)
        print("\n".join(problems) if problems else f"identical to the files in {args.out}")
        return 1 if problems else 0

    mannequins = {BASE_FILE: base, **rms}
    changed = save_all(mannequins, args.out)
    args.docs.mkdir(parents=True, exist_ok=True)
    atomic_write_text(args.docs / "topology.md", topology_doc(base))
    atomic_write_text(args.docs / "reference_mannequins.md", measurements_doc(base, rms, report))
    print(f"{len(changed)} of {len(mannequins)} JSON files changed in {args.out}; docs written to {args.docs}")
    if not args.no_blend:
        # .blend and .png files are not byte-reproducible: rewrite only what changed (or is missing)
        stale = {stem: m for stem, m in mannequins.items()
                 if stem in changed or not (args.out / f"{stem}.blend").is_file()}
        if stale:
            write_blends(stale, args.out)
        print(f"{len(stale)} .blend files written")
        lineup = args.docs / "images" / "reference_lineup.png"
        if set(changed) & set(RM_BODIES) or not lineup.is_file():
            write_lineup([args.out / f"{stem}.json" for stem in LINEUP_ORDER], lineup)
    return 0


if __name__ == "__main__":
    sys.exit(main())
