"""Posing: a mannequin with its cushions moved to a pose per call (what following a dragged bone costs),
against the live synthesis step in the same run (the core work of one slider step: exact-mode synthesis and
the cushions' vertices), plus building the posing rig once and a whole walk cycle."""

import time

import numpy as np

from ellimann_addon.core.constants import CUSHION_LEVEL, LIVE_CUSHION_LEVEL, MJCF_CUSHION_LEVEL
from ellimann_addon.core.geometry.cushion import cushion_vertices
from ellimann_addon.core.pose.posed_pieces import PosingRig
from ellimann_addon.core.pose.standard import standard_pose, walk
from ellimann_addon.core.synthesis.reference_set import load_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize_batch

TARGET_MS = 16.0  # a frame at 60 Hz: what following a dragged bone needs
REQUEST = [165.0, 41.5, 101.25, 82.75, 117.5]


def median_ms(fn, count=30):
    times = []
    for _ in range(count):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return float(np.median(times)) * 1e3, float(np.max(times)) * 1e3


def run(quick=False):
    """``quick``: a few calls of each (checks that it runs)."""
    count, cycles = (2, 1) if quick else (30, 5)
    reference = load_reference_set()
    mannequin = synthesize_batch(reference, [REQUEST]).mannequin(0)
    pairs = mannequin.topology.cushion_pairs

    def live_step():
        result = synthesize_batch(reference, [REQUEST])
        cushion_vertices(result.rotation[0], result.center[0], result.semi_axes[0], pairs, LIVE_CUSHION_LEVEL)

    live, live_max = median_ms(live_step, count)
    print(
        f"live synthesis step (exact mode + {len(pairs)} cushions' vertices at level {LIVE_CUSHION_LEVEL}): "
        f"{live:7.2f} ms median, {live_max:.2f} max"
    )
    frames = walk(mannequin.joints)
    sitting = standard_pose("sit", mannequin.joints)
    for level in (MJCF_CUSHION_LEVEL, CUSHION_LEVEL):
        start = time.perf_counter()
        rig = PosingRig(mannequin, subdivisions=level)
        built = (time.perf_counter() - start) * 1e3
        vertices = sum(len(m.vertices) for m in rig.meshes)
        posing, posing_max = median_ms(lambda r=rig: r.pose(sitting), count)
        cycle, _ = median_ms(lambda r=rig: [r.pose(f) for f in frames], count=cycles)
        verdict = "under" if posing < TARGET_MS else "OVER"
        print(
            f"pose {len(mannequin)} pieces + {len(rig.meshes)} cushion meshes (level {level}, {vertices:,} vertices): "
            f"{posing:6.2f} ms median, {posing_max:.2f} max ({verdict} the {TARGET_MS:g} ms target; "
            f"{posing / live:.2f}x the live synthesis step); rig built once in {built:.0f} ms; "
            f"the 24-frame walk cycle {cycle:.0f} ms"
        )
