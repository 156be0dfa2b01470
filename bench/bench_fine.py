"""The fine topology against the paper's 40 in one run: what the extra pieces cost (m_T, exact mode, the live
step, posing, draping) as ratios, and exact mode on the paper's 243 grid on every shipped set.

Each cost is timed on the two sets' Average Reference Mannequins (or requests to them) in the same run,
interleaved, best of a few (the machine is shared: the ratio is what counts):

- m_T: one closed-form measurement of the Average RM (core.measure.tailor);
- exact mode: the 243 grid synthesized in exact mode, one batch;
- the live step: one request synthesized in exact mode plus the cushions' vertices at the live level (bench_pose);
- posing: the mannequin and its cushions moved to the sitting pose (core.pose.posed_pieces.PosingRig);
- draping: seconds per simulated frame of the tube dress on the Average RM (Blender's cloth; needs the bpy module).
"""

import itertools
import time

import numpy as np

from bench.bench_core import best_of
from bench.bench_pose import REQUEST, median_ms
from ellimann_addon.core.constants import CUSHION_LEVEL, LIVE_CUSHION_LEVEL, quartile_points
from ellimann_addon.core.geometry.cushion import cushion_vertices
from ellimann_addon.core.measure.tailor import tailor_measurements
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.pose.posed_pieces import PosingRig
from ellimann_addon.core.pose.standard import standard_pose
from ellimann_addon.core.synthesis.shipped import (
    FEMALE_FINE_SET,
    FEMALE_SET,
    MALE_FINE_SET,
    MALE_SET,
    named_reference_set,
)
from ellimann_addon.core.synthesis.synthesize import EXACT_TOLERANCE, synthesize_batch

PAIRS = ((FEMALE_SET, FEMALE_FINE_SET), (MALE_SET, MALE_FINE_SET))
DRAPE_FRAMES = 20
ROUNDS = 3  # of the core costs, each set timed in turn


def grid(reference):
    """The paper's 243 requests over the inner quartile points of the set's ranges."""
    return np.array(list(itertools.product(*[quartile_points(k, reference.ranges) for k in MEASUREMENTS])))


def average(reference):
    return reference.mannequins[reference.names.index("average")]


def costs(reference, quick=False):
    """{cost: seconds} of one set (see the module's docstring); ``quick``: 9 requests, each timed once."""
    mannequin = average(reference)
    girth = mannequin.topology.girth_mask
    args = (mannequin.rotation, mannequin.center, mannequin.semi_axes, girth, reference.section_fractions)
    requests = grid(reference)[:: 27 if quick else 1]
    repeat, count = (1, 1) if quick else (5, 30)
    pairs = mannequin.topology.cushion_pairs

    def live_step():
        result = synthesize_batch(reference, [REQUEST])
        cushion_vertices(result.rotation[0], result.center[0], result.semi_axes[0], pairs, LIVE_CUSHION_LEVEL)

    rig = PosingRig(mannequin, subdivisions=CUSHION_LEVEL)
    sitting = standard_pose("sit", mannequin.joints)
    return {
        "m_T (one mannequin)": best_of(lambda: tailor_measurements(*args), repeat=repeat, number=1 if quick else 20),
        f"exact mode ({len(requests)} requests)": best_of(
            lambda: synthesize_batch(reference, requests, mode="exact"), repeat=1 if quick else 2
        ),
        "live step": median_ms(live_step, count)[0] * 1e-3,
        "posing (sit, cushions level 4)": median_ms(lambda: rig.pose(sitting), count)[0] * 1e-3,
    }


def drape_seconds(mannequins, repeat=2, frames=DRAPE_FRAMES):
    """Seconds per simulated frame of the tube dress on each mannequin (best of ``repeat``, interleaved), or None
    without the bpy module."""
    try:
        import bpy  # noqa: F401
    except ImportError:
        return None
    import ellimann_addon
    from ellimann_addon.blender.services import drape
    from ellimann_addon.blender.services.chatter import blender_output
    from ellimann_addon.blender.services.scene import empty_scene

    ellimann_addon.register()
    try:
        best = [np.inf] * len(mannequins)
        for _ in range(repeat):
            for k, mannequin in enumerate(mannequins):
                with blender_output():
                    empty_scene()
                    result = drape.drape(mannequin, "tube_dress", drape.DrapeSettings(frames=frames))
                best[k] = min(best[k], result.seconds_per_frame)
        return best
    finally:
        ellimann_addon.unregister()


def exactness(reference, step=1):
    """(converged share, largest relative error %) of exact mode on the set's 243 grid (every ``step``-th request)."""
    result = synthesize_batch(reference, grid(reference)[::step], mode="exact")
    return float(result.converged.mean()), float(result.relative_error().max())


def run(quick=False):
    """``quick``: one round of a few requests, a 2-frame drape, exact mode on every 27th request (checks that it
    runs)."""
    rounds, frames = (1, 2) if quick else (ROUNDS, DRAPE_FRAMES)
    coarse, fine = (named_reference_set(name) for name in PAIRS[0])
    print(
        f"costs on the Average RM: {coarse.name} ({len(coarse.topology)} parts, "
        f"{len(coarse.topology.cushion_pairs)} cushions) vs {fine.name} ({len(fine.topology)} parts, "
        f"{len(fine.topology.cushion_pairs)} cushions); seconds, best of a few, interleaved"
    )
    started = time.perf_counter()
    first, second = {}, {}
    for _ in range(rounds):  # the two sets in turn, the best of each: load drifts
        for best, reference in ((first, coarse), (second, fine)):
            for key, seconds in costs(reference, quick).items():
                best[key] = min(best.get(key, np.inf), seconds)
    drape = drape_seconds([average(coarse), average(fine)], 1 if quick else 2, frames)
    if drape is not None:
        first[f"drape (tube dress, s/frame over {frames} frames)"] = drape[0]
        second[f"drape (tube dress, s/frame over {frames} frames)"] = drape[1]
    print(f"| cost | {coarse.name} | {fine.name} | ratio |")
    print("|---|---|---|---|")
    for key in first:
        print(f"| {key} | {first[key] * 1e3:.2f} ms | {second[key] * 1e3:.2f} ms | {second[key] / first[key]:.2f}x |")
    if drape is None:
        print("(draping skipped: no bpy module)")
    print(f"(timed in {time.perf_counter() - started:.0f} s)")
    print(f"exact mode on the 243 grid (target: every request within {100 * EXACT_TOLERANCE:g} %):")
    for names in PAIRS:
        for name in names:
            converged, worst = exactness(named_reference_set(name), 27 if quick else 1)
            print(f"  {name:12s} converged {converged:.1%}, largest relative error {worst:.5f} %")


if __name__ == "__main__":
    run()
