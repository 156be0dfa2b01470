"""Exact mode on the skin with and without the six extra measurements, on a grid of requests: the skin's error to
the request on its own mesh, the rounds and the time.

The grid (GRID): reference bodies' own measurements (the five as their README measures them, the six as the
body-mesh measurer takes them: tools.shipped.bodies.body_requests), with and without the six, on both sets; and Table
2.5 requests with the set's own extra measurements 6 % up or down. Each request: a mannequin synthesized from
the five (exact mode), then ``core.skin.exact.exact_skin`` at the preview and the final level. Printed per
request and level: the rounds, the seconds (wall clock, this process; the machine is shared: read them as a
rough scale), the largest error of the five and of the extra ones on the skin's mesh (mm) and of the pieces'
own m_T and extra measurements (mm: what the blend adds, which the loop asks the pieces to leave out).
"""

import time

import numpy as np

from ellimann_addon.core.constants import TABLE_2_5
from ellimann_addon.core.mannequin.skin_record import SkinSettings
from ellimann_addon.core.measure.extra import mannequin_extra_measurements
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ellimann_addon.core.settings import LEVELS
from ellimann_addon.core.skin.exact import exact_skin
from ellimann_addon.core.synthesis.shipped import named_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize
from tools.shipped.bodies import body_requests, load_labels
from tools.shipped.reference_sets import BUILD_SETS, TRACING_FOLDER

# (set, body or Table 2.5 row, extra measurements: "none", "own" (the body's) or a ratio to what the set gives)
GRID = (
    ("female", "small_slim", "none"),
    ("female", "small_slim", "own"),
    ("female", "tall_chubby", "none"),
    ("female", "tall_chubby", "own"),
    ("female", 4, 1.06),
    ("female", 9, 0.94),
    ("male", "tall_slim", "own"),
)
MM_PER_CM = 10.0


def grid_request(reference, set_name, body, extra):
    """(five {cm}, extra {cm}) of a GRID row (``reference``: the set's ReferenceSet)."""
    if isinstance(body, int):
        five = dict(zip(MEASUREMENTS, TABLE_2_5[body]))
        own = mannequin_extra_measurements(synthesize(reference, TABLE_2_5[body])[0])
        return five, {key: extra * own[key] for key in EXTRA_MEASUREMENTS}
    five, six = body_requests(BUILD_SETS[set_name], load_labels(TRACING_FOLDER), [body])[body]
    return five, (six if extra == "own" else {})


def run(levels=tuple(LEVELS), grid=GRID, quick=False):
    """``quick``: the grid's first request with its own extra measurements (row 2), at the preview level (checks that
    it runs)."""
    if quick:
        levels, grid = ("preview",), GRID[1:2]
    sets = {name: named_reference_set(name) for name in ("female", "male")}
    print(
        f"{'request':<28}{'level':>8}{'rounds':>7}{'s':>7} | skin's error, mm: {'five':>6}{'extra':>7} | "
        f"pieces' error, mm: {'five':>6}{'extra':>7}"
    )
    worst = {level: [0.0, 0.0] for level in levels}
    for set_name, body, extra in grid:
        reference = sets[set_name]
        five, six = grid_request(reference, set_name, body, extra)
        mannequin = synthesize(reference, list(five.values()))[0]
        label = f"{set_name} {body if isinstance(body, str) else f'T2.5 #{body + 1}'} {extra}"
        for level in levels:
            start = time.perf_counter()
            result = exact_skin(mannequin, SkinSettings.at_level(level), five, six)
            seconds = time.perf_counter() - start
            skin = [abs(result.skin_measured[k] - result.request[k]) * MM_PER_CM for k in result.request]
            pieces = [abs(result.pieces_measured[k] - result.request[k]) * MM_PER_CM for k in result.request]
            cells = [max(skin[:5]), max(skin[5:], default=np.nan), max(pieces[:5]), max(pieces[5:], default=np.nan)]
            worst[level] = [max(worst[level][0], cells[0]), np.nanmax([worst[level][1], cells[1]])]
            shown = [f"{cell:.2f}" if np.isfinite(cell) else "-" for cell in cells]
            print(
                f"{label:<28}{level:>8}{result.rounds:>7}{seconds:>7.1f} | {'':17}{shown[0]:>6}{shown[1]:>7}"
                f" | {'':18}{shown[2]:>6}{shown[3]:>7}" + ("" if result.converged else "  NOT CONVERGED")
            )
    for level, (five_mm, extra_mm) in worst.items():
        print(f"{level}: the skin's largest error on the grid: the five {five_mm:.2f} mm, the extra {extra_mm:.2f} mm")


if __name__ == "__main__":
    run()
