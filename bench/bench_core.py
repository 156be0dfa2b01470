"""Geometry core: m_T closed form vs brute force, batched m_T throughput, cushion build time."""

import time

import numpy as np

from devkit.reference import brute_force_measure, random_mannequin_arrays
from ellimann_addon.core.geometry import cushion
from ellimann_addon.core.measure import tailor as measure


def best_of(fn, repeat=5, number=1):
    """Best wall time per call (s) over ``repeat`` runs of ``number`` calls: least disturbed by load."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(number):
            fn()
        times.append((time.perf_counter() - start) / number)
    return min(times)


def run(quick=False):
    """``quick``: a few bodies, the coarsest brute force, one repetition (checks that it runs; figures mean nothing)."""
    rng = np.random.default_rng(2026)
    count, truth_samples, repeat = (3, 20_000, 1) if quick else (20, 200_000, 3)
    bodies = [random_mannequin_arrays(rng, 40) for _ in range(count)]
    girth = bodies[0][3]
    bodies = [(r, c, d, girth) for r, c, d, _ in bodies]
    checked = bodies[:5]
    truth = [brute_force_measure(*b, samples=truth_samples) for b in checked]

    def rel_error(fn):
        return max(np.max(np.abs(fn(*b) - t) / t) for b, t in zip(checked, truth))

    closed_err = rel_error(measure.tailor_measurements)
    closed_t = best_of(lambda: [measure.tailor_measurements(*b) for b in bodies], repeat=repeat) / len(bodies)
    print(
        f"m_T on one 40-ellipsoid mannequin (random bodies; truth = brute force at {truth_samples // 1000}k "
        "samples/ellipse)"
    )
    print(f"  closed form (Cauchy + exact kinks)  {closed_t * 1e3:8.3f} ms   max rel error {closed_err:.1e}")
    for samples in (1_000,) if quick else (1_000, 10_000, 50_000):
        err = rel_error(lambda *b, s=samples: brute_force_measure(*b, samples=s))
        t = best_of(lambda s=samples: [brute_force_measure(*b, samples=s) for b in checked], repeat=repeat) / len(
            checked
        )
        verdict = "worse" if err > closed_err else "equal or better"
        print(
            f"  brute force, {samples:6d} samples    {t * 1e3:8.3f} ms   max rel error {err:.1e}  "
            f"({verdict} accuracy; closed form is {t / closed_t:6.1f}x faster)"
        )

    batch = 20 if quick else 1000
    stacked = [np.stack([bodies[i % len(bodies)][j] for i in range(batch)]) for j in range(3)]
    t = best_of(lambda: measure.tailor_measurements(*stacked, girth), repeat=repeat)
    print(
        f"m_T batched over {batch} mannequins: {t:.3f} s = {t / batch * 1e3:.3f} ms each, {batch / t:,.0f} mannequins/s"
    )

    eye = np.eye(3)
    pair = ((eye, (0, 0, 0), (0.06, 0.07, 0.2)), (eye, (0.01, 0.02, -0.35), (0.045, 0.05, 0.18)))
    print("cushion (thigh-like pair), per subdivision level:")
    for s in (2,) if quick else (2, 3, 4, 5):
        t = best_of(lambda s=s: cushion.cushion_mesh(*pair, subdivisions=s), repeat=repeat)
        v, f = cushion.cushion_mesh(*pair, subdivisions=s)
        print(f"  subdivisions {s}: {len(v):6d} vertices {len(f):6d} faces  {t * 1e3:8.2f} ms")


if __name__ == "__main__":
    run()
