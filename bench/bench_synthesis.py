"""The paper's experiment (Section 2.4.1, Table 2.4) and synthesis throughput, core and in Blender.

243 requests: every combination of the three inner quartile points of L per measurement. Each is
synthesized, then measured with m_T; the relative error |m_T - request| / request is summarised per
measurement as in Table 2.4, for plain IDW (the paper's method) and for exact mode. Uses the shipped
Reference Mannequins when ``reference_blends/`` holds them, else the synthetic set (say which).
"""

import itertools
import os
import tempfile
import time

import numpy as np

from bench.bench_core import best_of
from devkit.synthetic import shipped_or_synthetic
from ellimann_addon.core import synthesis
from ellimann_addon.core.constants import MEASUREMENTS, PAPER_TABLE_2_4, quartile_points
from ellimann_addon.core.measure import tailor_measurements


def grid():
    return np.array(list(itertools.product(*[quartile_points(k) for k in MEASUREMENTS])))


def table(title, error, paper=True):
    print(title)
    print("  relative error %   " + "".join(f"{k:>14}" for k in MEASUREMENTS))
    for label, values in (("mean", error.mean(axis=0)), ("max", error.max(axis=0)), ("min", error.min(axis=0))):
        cells = "".join(f"{v:8.3f}" + (f" ({PAPER_TABLE_2_4[label][k]:3.1f})" if paper else " " * 6)
                        for v, k in zip(values, MEASUREMENTS))
        print(f"  {label:<18} {cells}")
    if paper:
        print("  (in brackets: the paper's Table 2.4)")


def run():
    reference, label = shipped_or_synthetic()
    requests = grid()
    girth = reference.topology.girth_mask
    n = len(reference.topology)
    print(f"reference set: {label}, {len(reference)} RMs x {n} ellipsoids; grid: {len(requests)} requests")

    results = {}
    for mode in synthesis.MODES:
        start = time.perf_counter()
        results[mode] = synthesis.synthesize_batch(reference, requests, mode=mode)
        seconds = time.perf_counter() - start
        table(f"\nTable 2.4, {mode} (raw cm distance, p = 2), synthesized + measured in {seconds:.2f} s",
              results[mode].relative_error())
    exact = results["exact"]
    spread = np.abs(exact.factors - 1.0) * 100.0
    print(f"exact mode: {exact.converged.sum()}/{len(exact)} converged (tolerance "
          f"{synthesis.EXACT_TOLERANCE * 100:g}%); deformation |factor - 1| % mean / max per measurement: "
          + ", ".join(f"{k} {m:.2f}/{x:.2f}" for k, m, x in zip(MEASUREMENTS, spread.mean(0), spread.max(0))))
    idw = results["idw"]
    ratio = np.abs(exact.semi_axes / idw.semi_axes - 1.0) * 100.0
    shift = np.linalg.norm(exact.center - idw.center, axis=-1) * 100.0
    print(f"exact vs IDW, per ellipsoid: semi-axis change median {np.median(ratio):.2f}%, 99th percentile "
          f"{np.percentile(ratio, 99):.1f}%, max {ratio.max():.1f}%; centre shift 99th percentile "
          f"{np.percentile(shift, 99):.2f} cm, max {shift.max():.2f} cm")
    normalized = synthesis.synthesize_batch(reference, requests, metric="normalized")
    table("\nfor comparison, idw with distances normalized by the ranges L", normalized.relative_error(), paper=False)

    print("\nthroughput (core, one process, best of 3):")
    batch = len(requests)
    t_idw = best_of(lambda: synthesis.interpolate(reference, requests), repeat=3)
    rotation, center, semi_axes = synthesis.interpolate(reference, requests)
    t_mt = best_of(lambda: tailor_measurements(rotation, center, semi_axes, girth), repeat=3)
    t_exact = best_of(lambda: synthesis.synthesize_batch(reference, requests, mode="exact"), repeat=3)
    print(f"  IDW synthesis, batched {batch:>4}          {batch / t_idw:10,.0f} mannequins/s  ({t_idw * 1e3:7.1f} ms)")
    print(f"  m_T, batched {batch:>4}                   {batch / t_mt:10,.0f} mannequins/s  ({t_mt * 1e3:7.1f} ms)")
    print(f"  exact mode (IDW + m_T + refinement) {batch / t_exact:10,.0f} mannequins/s  ({t_exact * 1e3:7.1f} ms)")
    one = requests[121:122]
    for mode in synthesis.MODES:
        t = best_of(lambda mode=mode: synthesis.synthesize_batch(reference, one, mode=mode), repeat=5, number=5)
        print(f"  one request, {mode:<5} (with m_T)        {t * 1e3:8.2f} ms")

    blender(reference, exact)


def blender(reference, exact):
    """Building collections, live updates and files in Blender (bpy module)."""
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="ellimann-bench-"))
    import bpy

    import ellimann_addon
    from ellimann_addon.blender import convert, output

    ellimann_addon.register()
    try:
        bpy.ops.wm.read_homefile(use_empty=True)
        mannequins = [exact.mannequin(i) for i in range(40)]
        start = time.perf_counter()
        collections = [convert.mannequin_to_collection(m) for m in mannequins]
        t_build = (time.perf_counter() - start) / len(mannequins)
        print(f"\nBlender ({len(reference.topology)} ellipsoids per mannequin):")
        print(f"  build a mannequin collection       {1 / t_build:10,.0f} mannequins/s  ({t_build * 1e3:7.2f} ms)")
        target = collections[0]
        t_update = best_of(lambda: [convert.update_collection_geometry(target, m) for m in mannequins[1:11]],
                           repeat=3) / 10
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
            bpy.ops.ellimann.synthesize_mannequin()
            props.live = True
            times = []
            for value in np.linspace(150.0, 170.0, 21):
                start = time.perf_counter()
                props.he = float(value)
                times.append(time.perf_counter() - start)
            times = np.array(times) * 1e3
            print(f"  live update from the panel (exact) {np.median(times):8.2f} ms median, {times.max():.2f} ms max "
                  f"over {len(times)} slider steps")
            for kind in ("json", "blend", "glb", "obj"):
                path = os.path.join(folder, f"m.{kind}")
                t = best_of(lambda path=path: output.write_mannequin(mannequins[0], [path]), repeat=3)
                print(f"  write .{kind:<5} (one mannequin)          {t * 1e3:8.2f} ms")
    finally:
        ellimann_addon.unregister()


if __name__ == "__main__":
    run()
