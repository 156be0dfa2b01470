"""The paper's experiment (Section 2.4.1, Table 2.4) and synthesis throughput, core and in Blender.

243 requests: every combination of the three inner quartile points of L per measurement. Each is
synthesized, then measured with m_T; the relative error |m_T - request| / request is summarised per
measurement as in Table 2.4, for the paper's IDW (``normalize="none"``), ElliMann's proportional IDW
(the default), the height-only variant, and exact mode after each IDW, with the refinement's
deformation factors. Latency and throughput compare the old exact mode (the paper's IDW, then a
finite-difference Jacobian per mannequin) with the current one (proportional IDW, the RMs' mean
Jacobian) in the same run. In Blender: building collections, m_T of mannequins in the scene
(objects -> core arrays -> m_T, and the Measure operator), live updates with ellipsoids and with
cushions (before: every cushion rebuilt; now: moved in place; interleaved over the same slider
steps, so the ratio is fair under load), and file writing. Uses the shipped Reference Mannequins
when ``reference_blends/`` holds them, else the synthetic set (say which).
"""

import itertools
import os
import subprocess
import tempfile
import time

import numpy as np

from bench.bench_core import best_of
from devkit.hull_before import hull_perimeter_before
from devkit.synthetic import shipped_or_synthetic
from ellimann_addon.core.constants import PAPER_TABLE_2_4, SECTION_FRACTIONS, quartile_points
from ellimann_addon.core.formats.table import write_file
from ellimann_addon.core.geometry.ellipsoid import section_at_height
from ellimann_addon.core.measure.tailor import hull_perimeter, section_heights, tailor_measurements
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis import synthesize as synthesis

VARIANTS = (  # label, synthesize_batch options
    ("paper IDW (Eq. 2.1: normalize none, raw cm, p = 2)", {"normalize": "none"}),
    ("proportional IDW (default)", {"normalize": "proportional"}),
    ("height-proportional IDW", {"normalize": "height"}),
    ("paper IDW, distances normalized by L", {"normalize": "none", "metric": "normalized"}),
    ("proportional IDW, distances normalized by L", {"normalize": "proportional", "metric": "normalized"}),
)


def grid():
    return np.array(list(itertools.product(*[quartile_points(k) for k in MEASUREMENTS])))


def table(title, error, paper=True):
    print(title)
    print("  relative error %   " + "".join(f"{k:>14}" for k in MEASUREMENTS))
    for label, values in (("mean", error.mean(axis=0)), ("max", error.max(axis=0)), ("min", error.min(axis=0))):
        cells = "".join(
            f"{v:8.3f}" + (f" ({PAPER_TABLE_2_4[label][k]:3.1f})" if paper else " " * 6)
            for v, k in zip(values, MEASUREMENTS)
        )
        print(f"  {label:<18} {cells}")
    if paper:
        print("  (in brackets: the paper's Table 2.4)")


def old_exact(reference, requests):
    """Exact mode as it was: the paper's IDW, then refinement from a finite-difference Jacobian."""
    rotation, center, semi_axes = synthesis.interpolate(reference, requests, normalize="none")
    measured = tailor_measurements(rotation, center, semi_axes, reference.topology.girth_mask)
    return synthesis.refine(reference.topology, rotation, center, semi_axes, requests, measured)


def deformation(title, result, seconds):
    spread = np.abs(result.factors - 1.0) * 100.0
    print(
        f"{title}: {result.converged.sum()}/{len(result.factors)} converged (tolerance "
        f"{synthesis.EXACT_TOLERANCE * 100:g}%) in {seconds:.2f} s; |factor - 1| % mean / max: "
        + ", ".join(f"{k} {m:.2f}/{x:.2f}" for k, m, x in zip(MEASUREMENTS, spread.mean(0), spread.max(0)))
    )


_err = synthesis.relative_error  # |a - b| / b in %


def _stat(values):
    return f"{values.mean():5.2f} /{values.max():6.2f}"


def _section(rotation, center, semi_axes, z, parts, key):
    """Sh (x extent over ``parts``) or a girth perimeter of the section at heights z (B,), in cm."""
    centre, k, hit = section_at_height(rotation, center, semi_axes, z[:, None])
    hit = hit & parts
    if key == "Sh":
        half = np.sqrt(k[..., 0, 0])
        right = np.where(hit, centre[..., 0] + half, -np.inf).max(axis=-1)
        left = np.where(hit, centre[..., 0] - half, np.inf).min(axis=-1)
        return (right - left) * 100.0
    return hull_perimeter(centre, k, hit) * 100.0


def diagnose(reference, requests):
    """Where the paper's IDW error comes from, per measurement (mean / max over the grid, in % or cm).

    The parts that depend on X are placed with the IDW weights of X's sub-space; their weighted mean
    He is the height they are built for, their weighted mean X the size. Moving the section to that
    height takes out the vertical misplacement; comparing the weighted mean X with the request shows
    what IDW's own averaging of the measurement misses; what is left is m_T's non-linearity (a
    blended body does not measure as the blend of the measurements). Foreign parts: parts that do not
    depend on X but change it (cut by its girth section, or outermost at the shoulders), and by how much.
    """
    topology = reference.topology
    weights = synthesis.idw_weights(reference, requests)
    rotation, center, semi_axes = synthesis.interpolate(reference, requests, normalize="none")
    girth = topology.girth_mask
    measured = tailor_measurements(rotation, center, semi_axes, girth)
    bottom, _, z = section_heights(rotation, center, semi_axes)
    source = list(reference._source)
    print("\nwhy the paper's IDW misses (mean / max over the grid, % unless cm):")
    he_only = [row for row, part in enumerate(source) if topology.dependency_mask[part].sum() == 1]
    if he_only:
        implied = weights[:, he_only[0]] @ reference.measurements
        error = _err(implied[:, 0], requests[:, 0])
        print(
            f"  He: paper IDW {_stat(_err(measured[:, 0], requests[:, 0]))}; "
            f"the head (on He alone) is built for sum_j w_j He_j, off by {_stat(error)}"
        )
    for index, key in enumerate(MEASUREMENTS[1:], start=1):
        own = topology.dependency_mask[:, index]
        rows = [row for row, part in enumerate(source) if own[part]]
        if not rows:
            continue
        implied = weights[:, rows[0]] @ reference.measurements  # (B, 5) what the parts of X are built for
        placed = bottom + SECTION_FRACTIONS[key] * implied[:, 0] / 100.0
        parts = np.ones_like(girth) if key == "Sh" else girth
        moved = _section(rotation, center, semi_axes, placed, parts, key)
        own_only = _section(rotation, center, semi_axes, z[key], parts & own, key)
        foreign = np.abs(measured[:, index] - own_only) > 1e-9
        added = 100.0 * (measured[:, index] - own_only) / measured[:, index]  # share the foreign parts add
        target = requests[:, index]
        print(
            f"  {key}: paper IDW {_stat(_err(measured[:, index], target))}; its parts are "
            f"built for an He off by {_stat(_err(implied[:, 0], requests[:, 0]))} "
            f"(section {_stat(np.abs(placed - z[key]) * 100.0)} cm off); with the section moved there "
            f"{_stat(_err(moved, target))}\n"
            f"      of which sum_j w_j {key}_j vs {key} {_stat(_err(implied[:, index], target))}"
            f" + m_T non-linearity {_stat(_err(moved, implied[:, index]))}; "
            f"parts of other measurements change it in {foreign.sum()} mannequins, by "
            f"{_stat(added)}"
        )


def reference_version():
    """The last commit that changed reference_blends/ (the numbers depend on the RMs), + local changes."""

    def git(*args):
        return subprocess.run(
            ["git", *args, "--", "reference_blends"],
            capture_output=True,
            text=True,
            check=True,
            cwd=os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
        ).stdout.strip()

    try:
        commit = git("log", "-1", "--format=%h %cs") or "uncommitted"
        return commit + (" + local changes" if git("status", "--porcelain") else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def run(quick=False):
    """``quick``: every 27th request of the grid (9), one repetition, a few slider steps (checks that it runs)."""
    reference, label = shipped_or_synthetic()
    requests = grid()[::27] if quick else grid()
    repeat = 1 if quick else 3
    girth = reference.topology.girth_mask
    n = len(reference.topology)
    version = f", reference_blends at {reference_version()}" if label.startswith("shipped") else ""
    print(f"reference set: {label}{version}, {len(reference)} RMs x {n} ellipsoids; grid: {len(requests)} requests")

    diagnose(reference, requests)
    results = {}
    for title, options in VARIANTS:
        start = time.perf_counter()
        results[title] = synthesis.synthesize_batch(reference, requests, mode="idw", **options)
        seconds = time.perf_counter() - start
        table(
            f"\nTable 2.4, {title}: synthesized + measured in {seconds:.2f} s",
            results[title].relative_error(),
            paper=options.get("metric", "raw") == "raw",
        )

    start = time.perf_counter()
    exact = synthesis.synthesize_batch(reference, requests, mode="exact")
    t_exact = time.perf_counter() - start
    table(f"\nTable 2.4, exact mode (after proportional IDW), in {t_exact:.2f} s", exact.relative_error())
    start = time.perf_counter()
    old = old_exact(reference, requests)
    t_old = time.perf_counter() - start
    old_error = synthesis.relative_error(old.measured, requests)
    table(f"\nTable 2.4, exact mode after the paper's IDW (finite-difference start), in {t_old:.2f} s", old_error)
    print()
    deformation("exact after paper IDW       ", old, t_old)
    deformation("exact after proportional IDW", exact, t_exact)
    now = synthesis.refine(
        reference.topology, *synthesis.interpolate(reference, requests), requests, jacobian=reference.refine_jacobian()
    )
    print(f"  iterations (slowest mannequin): {old.iterations} after paper IDW, {now.iterations} after proportional")
    for title, start, end in (
        ("exact vs paper IDW       ", results[VARIANTS[0][0]], old),
        ("exact vs proportional IDW", results[VARIANTS[1][0]], exact),
    ):
        ratio = np.abs(end.semi_axes / start.semi_axes - 1.0) * 100.0
        shift = np.linalg.norm(end.center - start.center, axis=-1) * 100.0
        print(
            f"{title}, per ellipsoid: semi-axis change median {np.median(ratio):.2f}%, 99th percentile "
            f"{np.percentile(ratio, 99):.1f}%, max {ratio.max():.1f}%; centre shift 99th percentile "
            f"{np.percentile(shift, 99):.2f} cm, max {shift.max():.2f} cm"
        )
    print(f"\nthroughput (core, one process, best of {repeat}):")
    batch = len(requests)
    t_idw = best_of(lambda: synthesis.interpolate(reference, requests), repeat=repeat)
    t_paper = best_of(lambda: synthesis.interpolate(reference, requests, normalize="none"), repeat=repeat)
    rotation, center, semi_axes = synthesis.interpolate(reference, requests)
    t_mt = best_of(lambda: tailor_measurements(rotation, center, semi_axes, girth), repeat=repeat)
    t_exact = best_of(lambda: synthesis.synthesize_batch(reference, requests, mode="exact"), repeat=repeat)
    t_old = best_of(lambda: old_exact(reference, requests), repeat=repeat)
    for name, seconds in (
        (f"paper IDW, batched {batch}", t_paper),
        (f"proportional IDW, batched {batch}", t_idw),
        (f"m_T, batched {batch}", t_mt),
        ("exact mode, before (paper IDW + FD)", t_old),
        ("exact mode, now", t_exact),
    ):
        print(f"  {name:<37}{batch / seconds:10,.0f} mannequins/s  ({seconds * 1e3:7.1f} ms)")
    print(f"  exact mode batched: {t_old / t_exact:.1f}x faster than before")
    print(
        f"  exact mode costs {t_exact / t_idw:.2f}x proportional IDW, m_T {t_mt / t_idw:.2f}x (wall time; the CPU "
        f"time ratios below are steadier)"
    )
    population_scale(reference, requests, repeat=1 if quick else 5)
    exact_parts(reference, requests, repeat=1 if quick else 5)
    one = requests[len(requests) // 2 :][:1]  # the grid's middle request (121 of 243)
    exact_parts(reference, one, repeat=1 if quick else 30)
    t_one = {}
    for name, fn in (
        ("idw, paper", lambda: synthesis.synthesize_batch(reference, one, mode="idw", normalize="none")),
        ("idw, proportional", lambda: synthesis.synthesize_batch(reference, one, mode="idw")),
        ("exact, before", lambda: old_exact(reference, one)),
        ("exact, now", lambda: synthesis.synthesize_batch(reference, one, mode="exact")),
    ):
        t_one[name] = best_of(fn, repeat=1 if quick else 5, number=1 if quick else 5)
        print(f"  one request, {name:<18} (with m_T) {t_one[name] * 1e3:8.2f} ms")
    print(f"  one request, exact: {t_one['exact, before'] / t_one['exact, now']:.1f}x faster than before")
    singles = []
    for request in requests[::4]:
        start = time.perf_counter()
        synthesis.synthesize_batch(reference, request[None], mode="exact")
        singles.append(time.perf_counter() - start)
    print(
        f"  one request at a time, exact, over {len(singles)} grid requests: median "
        f"{np.median(singles) * 1e3:.2f} ms, max {np.max(singles) * 1e3:.2f} ms"
    )

    blender(reference, exact, quick)


def _searching_before(centre, k, active, warm=None, structure=False):
    """devkit.hull_before's hull perimeter where m_T calls today's: it searches every time (``warm`` unused), and the
    structure it hands back is empty, so the refinement's later steps search too."""
    from ellimann_addon.core.geometry.section_hull import HullStructure

    out = hull_perimeter_before(centre, k, active)
    return (out, HullStructure.empty(len(out))) if structure else out


def population_scale(reference, requests, repeat=5):
    """Exact mode against proportional IDW on the same batch, with today's m_T and the one it replaced
    (``devkit.hull_before``), every variant timed in turn within each round (best of ``repeat`` rounds), in CPU
    time (on a shared machine wall time mostly measures the other jobs): the ratios are the figures to read."""
    from ellimann_addon.core.measure import tailor as measure

    def previous_m_t(fn):
        def run():
            current = measure.hull_perimeter
            measure.hull_perimeter = _searching_before
            try:
                return fn()
            finally:
                measure.hull_perimeter = current

        return run

    rotation, center, semi_axes = synthesis.interpolate(reference, requests)
    girth, fractions = reference.topology.girth_mask, reference.section_fractions
    reference.refine_jacobian()
    variants = {
        "proportional IDW (interpolation)": lambda: synthesis.interpolate(reference, requests),
        "IDW + m_T (mode idw)": lambda: synthesis.synthesize_batch(reference, requests, mode="idw"),
        "m_T, now": lambda: tailor_measurements(rotation, center, semi_axes, girth, fractions),
        "m_T, before": previous_m_t(lambda: tailor_measurements(rotation, center, semi_axes, girth, fractions)),
        "exact, now": lambda: synthesis.synthesize_batch(reference, requests, mode="exact"),
        "exact, with the m_T before": previous_m_t(
            lambda: synthesis.synthesize_batch(reference, requests, mode="exact")
        ),
    }
    best = dict.fromkeys(variants, float("inf"))
    for _ in range(repeat):
        for name, fn in variants.items():
            start = time.process_time()  # CPU time: what the work costs, whatever else the machine runs
            fn()
            best[name] = min(best[name], time.process_time() - start)
    batch = len(requests)
    print(f"\npopulation scale (batch {batch}; CPU time of this process, variants interleaved, best of {repeat}):")
    for name, seconds in best.items():
        print(f"  {name:<37}{batch / seconds:10,.0f} mannequins/s  ({seconds * 1e3:7.1f} ms)")
    idw, measured = best["proportional IDW (interpolation)"], best["IDW + m_T (mode idw)"]
    now, before = best["exact, now"], best["exact, with the m_T before"]
    print(f"  m_T {best['m_T, before'] / best['m_T, now']:.2f}x faster than before")
    print(
        f"  ratios to proportional IDW (the interpolation): m_T {best['m_T, now'] / idw:.2f}x (before "
        f"{best['m_T, before'] / idw:.2f}x), exact {now / idw:.2f}x (before {before / idw:.2f}x); exact / IDW with "
        f"its m_T {now / measured:.2f}x (before {before / measured:.2f}x)"
    )


def exact_parts(reference, requests, repeat=5):
    """Where exact mode's CPU time goes, part by part: each function synthesize_batch and refine call, timed where
    it is called (time.process_time), best of ``repeat`` runs of synthesize_batch. What is neither IDW nor m_T is
    exact mode's own overhead (issue 14 asks for exact mode at about 2x IDW at most)."""
    from ellimann_addon.core.synthesis import refine as refine_module

    timed = {  # label: the (module, name) places where synthesize_batch and refine call it
        "validate_requests": [(synthesis, "validate_requests")],
        "IDW weights": [(synthesis, "idw_weights")],
        "interpolate (IDW)": [(synthesis, "interpolate")],
        "interpolate_joints": [(synthesis, "interpolate_joints")],
        "m_T of the IDW result": [(synthesis, "tailor_measurements"), (synthesis, "followed_measurements")],
        "refine": [(synthesis, "refine")],
        "  m_T in refine": [(refine_module, "tailor_measurements"), (refine_module, "followed_measurements")],
        "  _deform_basis": [(refine_module, "deform_basis")],
        "  deform": [(refine_module, "deform")],
        "follow_pieces": [(synthesis, "follow_pieces")],
        "check_plausible": [(synthesis, "check_plausible")],
    }
    spent = {}

    def clocked(label, fn):
        def run(*args, **kwargs):
            start = time.process_time()
            try:
                return fn(*args, **kwargs)
            finally:
                spent[label] += time.process_time() - start

        return run

    originals = [(module, name, getattr(module, name)) for places in timed.values() for module, name in places]
    best = {}
    reference.refine_jacobian()
    try:
        for label, places in timed.items():
            for module, name in places:
                setattr(module, name, clocked(label, getattr(module, name)))
        for _ in range(repeat):
            spent.update(dict.fromkeys(timed, 0.0))
            start = time.process_time()
            synthesis.synthesize_batch(reference, requests, mode="exact")
            total = time.process_time() - start
            idw = spent["IDW weights"] + spent["interpolate (IDW)"]
            m_t = spent["m_T of the IDW result"] + spent["  m_T in refine"]
            run = dict(
                spent,
                **{
                    "  refine's own loop": spent["refine"]
                    - spent["  m_T in refine"]
                    - spent["  _deform_basis"]
                    - spent["  deform"],
                    "exact mode (synthesize_batch)": total,
                    "  IDW": idw,
                    "  m_T": m_t,
                    "  neither IDW nor m_T": total - idw - m_t,
                },
            )
            best = {k: min(v, best.get(k, float("inf"))) for k, v in run.items()}
    finally:
        for module, name, fn in originals:
            setattr(module, name, fn)
    order = list(timed)
    order.insert(order.index("  deform") + 1, "  refine's own loop")
    print(
        f"\nexact mode part by part (batch {len(requests)}; CPU ms, best of {repeat} runs, each part timed where "
        "it is called):"
    )
    for label in order + ["exact mode (synthesize_batch)", "  IDW", "  m_T", "  neither IDW nor m_T"]:
        print(f"  {label:<37}{best[label] * 1e3:8.2f} ms")
    print(f"  exact mode besides IDW and m_T: {best['  neither IDW nor m_T'] / best['  IDW']:.2f}x IDW")


def blender(reference, exact, quick=False):
    """Building, measuring and moving collections, live updates and files in Blender (bpy module); ``quick``: a few
    mannequins and slider steps, one repetition."""
    repeat, steps = (1, 3) if quick else (3, 21)
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="ellimann-bench-"))
    import bpy

    import ellimann_addon
    from ellimann_addon.blender.bridge import convert
    from ellimann_addon.blender.services import files
    from ellimann_addon.blender.services.chatter import (
        blender_output,  # what Blender prints stays off the bench's lines
    )

    ellimann_addon.register()
    try:
        with blender_output():
            bpy.ops.wm.read_homefile(use_empty=True)
        mannequins = [exact.mannequin(i) for i in range(min(40, len(exact.measured)))]
        start = time.perf_counter()
        collections = [convert.mannequin_to_collection(m) for m in mannequins]
        t_build = (time.perf_counter() - start) / len(mannequins)
        print(f"\nBlender ({len(reference.topology)} ellipsoids per mannequin):")
        print(f"  build a mannequin collection       {1 / t_build:10,.0f} mannequins/s  ({t_build * 1e3:7.2f} ms)")
        measure_in_blender(bpy, convert, collections, repeat)
        target, moved = collections[0], mannequins[1:11]
        t_update = best_of(lambda: [convert.update_collection_geometry(target, m) for m in moved], repeat=repeat) / len(
            moved
        )
        print(f"  move one in place (live update)     {t_update * 1e3:8.2f} ms")

        with tempfile.TemporaryDirectory() as folder:
            folder = os.path.abspath(folder)
            scene = bpy.context.scene
            props = scene.ellimann_synthesis
            if reference.sources[0] != reference.names[0]:  # loaded from files: point the panel at them
                props.references = os.path.dirname(reference.sources[0])
            else:
                from devkit.synthetic import write_reference_folder

                props.references = str(write_reference_folder(os.path.join(folder, "rm")))
            times = []
            with blender_output():
                bpy.ops.ellimann.synthesize_mannequin()
                props.live = True
                for value in np.linspace(150.0, 170.0, steps):
                    start = time.perf_counter()
                    props.he = float(value)
                    times.append(time.perf_counter() - start)
            times = np.array(times) * 1e3
            print(
                f"  live update from the panel (exact) {np.median(times):8.2f} ms median, {times.max():.2f} ms max "
                f"over {len(times)} slider steps"
            )
            live_with_cushions(bpy, props, steps)
            for kind in ("json", "blend", "glb", "obj"):
                path = os.path.join(folder, f"m.{kind}")
                if kind in ("json", "obj"):  # the core writes them, without Blender
                    t = best_of(lambda path=path: write_file(mannequins[0], path), repeat=repeat)
                else:
                    t = best_of(lambda path=path: files.write_mannequin(mannequins[0], [path]), repeat=repeat)
                print(f"  write .{kind:<5} (one mannequin)          {t * 1e3:8.2f} ms")
    finally:
        ellimann_addon.unregister()


def measure_in_blender(bpy, convert, collections, repeat=3):
    """m_T of mannequins in the scene: objects -> core arrays -> m_T, and the Measure operator."""
    t_read = best_of(lambda: [convert.collection_to_mannequin(c) for c in collections], repeat=repeat) / len(
        collections
    )
    read = [convert.collection_to_mannequin(c) for c in collections]
    t_core = best_of(lambda: [m.measure() for m in read], repeat=repeat) / len(collections)
    t_mt = best_of(lambda: [convert.collection_to_mannequin(c).measure() for c in collections], repeat=repeat) / len(
        collections
    )
    print(
        f"  measure (read objects + m_T)       {1 / t_mt:10,.0f} mannequins/s  ({t_mt * 1e3:7.2f} ms: reading "
        f"{t_read * 1e3:.2f} ms, m_T {t_core * 1e3:.2f} ms, best of {repeat} each)"
    )

    shown = collections[:10]

    def operator():
        for collection in shown:
            bpy.context.view_layer.objects.active = collection.objects[0]
            bpy.ops.ellimann.measure_mannequin(source="ELLIPSOIDS")

    from ellimann_addon.blender.services.chatter import blender_output

    with blender_output():  # the operator reports m_T on stdout
        t_op = best_of(operator, repeat=repeat) / len(shown)
    print(f"  Measure operator (ellipsoids)      {1 / t_op:10,.0f} mannequins/s  ({t_op * 1e3:7.2f} ms)")


def old_live_update(props, target, output, convert):
    """A live update as it was before in-place cushions: every cushion rebuilt at 642 vertices."""
    from ellimann_addon.blender.features.synthesize.request import synthesize_request
    from ellimann_addon.core.constants import LIVE_CUSHION_LEVEL

    mannequin, measured, _ = synthesize_request(props)
    convert.update_collection_geometry(target, mannequin)
    convert.write_measured(target, measured)
    output.refresh_cushions(target, LIVE_CUSHION_LEVEL)
    if target.name != mannequin.name:
        target.name = mannequin.name


def live_with_cushions(bpy, props, steps=21):
    """Live updates of a cushion mannequin: before (rebuild every cushion) and now (move them in place),
    interleaved over the same slider steps; then the exact rebuild once the slider stops."""
    from ellimann_addon.blender.bridge import convert
    from ellimann_addon.blender.bridge.built import built_objects
    from ellimann_addon.blender.features.synthesize import live, presets
    from ellimann_addon.blender.services import scene as output
    from ellimann_addon.blender.services.chatter import blender_output

    props.live = False
    props.output = "CUSHIONS"
    props.he = 159.0  # not a slider step: the last step leaves the cushions out of date
    now, before = [], []
    with blender_output():
        bpy.ops.ellimann.synthesize_mannequin()
        before_target = props.target
        bpy.ops.ellimann.synthesize_mannequin()
        props.live = True  # the second one is the live target
        pairs = len(built_objects(props.target, "CUSHION"))
        for value in np.linspace(150.0, 170.0, steps):
            start = time.perf_counter()
            props.he = float(value)  # the panel's update callback
            now.append(time.perf_counter() - start)
            start = time.perf_counter()
            old_live_update(props, before_target, output, convert)
            before.append(time.perf_counter() - start)
    now, before = np.array(now) * 1e3, np.array(before) * 1e3
    print(f"  live update with {pairs} cushions, {len(now)} slider steps (interleaved, same requests):")
    print(f"    before: rebuild every cushion     {np.median(before):8.2f} ms median, {before.max():.2f} ms max")
    print(f"    now: move them in place          {np.median(now):8.2f} ms median, {now.max():.2f} ms max")
    print(f"    {np.median(before) / np.median(now):.1f}x faster (median), {before.max() / now.max():.1f}x (max)")
    start = time.perf_counter()
    with blender_output():
        rebuilt = live.settle_live(bpy.context.scene)
    print(
        f"    exact rebuild once the slider stops ({rebuilt} cushions, "
        f"{live.LIVE_SETTLE_SECONDS:g} s later): {(time.perf_counter() - start) * 1e3:.0f} ms"
    )
    calls = []
    real = live.live_update
    live.live_update = lambda scene: calls.append(time.perf_counter()) or real(scene)
    try:
        preset = presets.SHIPPED_PRESETS / "Table 2.5 (1).py"
        start = time.perf_counter()
        with blender_output():
            bpy.ops.script.execute_preset(filepath=str(preset), menu_idname="ELLIMANN_MT_measurement_presets")
        seconds = time.perf_counter() - start
    finally:
        live.live_update = real
    print(f"    a preset (five fields): {len(calls)} live update, {seconds * 1e3:.0f} ms")
    props.live = False
    props.output = "ELLIPSOIDS"


if __name__ == "__main__":
    run()
