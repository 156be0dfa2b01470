"""The paper's experiment (Section 2.4.1, Table 2.4) on the male reference set (reference_blends/male/).

243 requests: every combination of the three inner quartile points of the male ranges L. Each is synthesized
with the paper's IDW (``normalize="none"``), proportional IDW (the default) and exact mode, and measured with
m_T at the male section heights; the relative error |m_T - request| / request is summarised per measurement
as Table 2.4 is (mean / max / min, %); then the cost of exact mode against proportional IDW (bench_synthesis.
population_scale). The female set's figures are bench_synthesis's.
"""

import itertools
import time

import numpy as np

from bench.bench_synthesis import population_scale, table
from ellimann_addon.core.constants import quartile_points
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis import synthesize as synthesis
from ellimann_addon.core.synthesis.shipped import MALE_SET, named_reference_set

VARIANTS = (
    ("the paper's IDW", {"mode": "idw", "normalize": "none"}),
    ("proportional IDW (default)", {"mode": "idw", "normalize": "proportional"}),
    ("exact mode (default)", {"mode": "exact"}),
)


def male_grid(reference):
    return np.array(list(itertools.product(*[quartile_points(key, reference.ranges) for key in MEASUREMENTS])))


def run(quick=False):
    """``quick``: every 27th request of the grid (9), one repetition (checks that it runs)."""
    reference = named_reference_set(MALE_SET)
    requests = male_grid(reference)[:: 27 if quick else 1]
    print(
        f"reference set: {reference.name} ({len(reference)} RMs), section heights "
        + ", ".join(f"{k} {v:g}" for k, v in reference.section_fractions.items())
        + f"; grid: {len(requests)} requests over the inner quartiles of "
        + ", ".join(f"{k} {lo:g}-{hi:g}" for k, (lo, hi) in reference.ranges.items())
    )
    for title, options in VARIANTS:
        start = time.perf_counter()
        result = synthesis.synthesize_batch(reference, requests, **options)
        seconds = time.perf_counter() - start
        table(f"\nTable 2.4 on the male set, {title}: {seconds:.2f} s", result.relative_error(), paper=False)
        if options["mode"] == "exact":
            spread = np.abs(result.factors - 1.0) * 100.0
            refined = synthesis.refine(
                reference.topology,
                *synthesis.interpolate(reference, requests),
                requests,
                jacobian=reference.refine_jacobian(),
                fractions=reference.section_fractions,
            )
            print(f"  iterations (slowest mannequin): {refined.iterations}")
            print(
                f"  converged: {int(result.converged.sum())}/{len(requests)} within "
                f"{synthesis.EXACT_TOLERANCE * 100:g}% (largest error {result.relative_error().max():.1e}%); "
                f"largest |factor - 1|: {spread.max():.2f}%"
            )
    population_scale(reference, requests, repeat=1 if quick else 5)
