"""The extra measurements on a mannequin (``core.measure.extra.mannequin_extra_measurements``) and exact mode
with them (``core.synthesis.extra_refine.meet_extra``): now against main's code before they were made faster
(``devkit.extra_before``: golden section per band, one hull_perimeter call a step), in one run.

Mannequins: the shipped female and male Reference Mannequins and mannequins synthesized (exact mode) on a grid
of requests over each set's inner quartiles. Per mannequin: the best of three timings of each way, the ratio,
and the largest difference of any extra measurement (cm). meet_extra: a few synthesized mannequins asked for
their extra measurements moved by a few per cent, timed once each way (main's measurements patched into
``core.synthesis.extra_refine`` for the before), with the largest difference of what each measured at the end.
"""

import itertools
import pathlib
import statistics
import tempfile
import time
from contextlib import contextmanager

import numpy as np

from devkit.extra_before import MannequinLandmarksBefore, mannequin_extra_measurements_before
from ellimann_addon.cli import MISSED
from ellimann_addon.cli import main as ellimann
from ellimann_addon.core.constants import quartile_points
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.measure import body as body_measure
from ellimann_addon.core.measure.extra import mannequin_extra_measurements
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ellimann_addon.core.synthesis import extra_refine as refine_extra
from ellimann_addon.core.synthesis import synthesize as synthesis
from ellimann_addon.core.synthesis.shipped import FEMALE_SET, MALE_SET, named_reference_set
from tools.shipped.reference_sets import TRACING_FOLDER

GRID_STEP = 27  # every 27th of the 243 inner-quartile requests: 9 per set
MEET_PER_SET = 2
EXTRA_CHANGE = (1.04, 0.97, 1.03, 1.05, 0.98, 1.02)  # per extra measurement, in EXTRA_MEASUREMENTS order


def synthesized(reference, step=GRID_STEP):
    """Mannequins synthesized in exact mode on every ``step``-th request of the set's inner-quartile grid."""
    requests = np.array(list(itertools.product(*[quartile_points(key, reference.ranges) for key in MEASUREMENTS])))
    batch = synthesis.synthesize_batch(reference, requests[::step])
    return [batch.mannequin(i, f"grid {i}") for i in range(len(batch.measured))]


def best_time(function, repeat=3):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return min(times), result


BODIES = ("reference_female", "small_slim", "tall_slim", "small_chubby", "tall_chubby", "average")


@contextmanager
def every_triangle_cut():
    """core.measure.body cutting every triangle of the mesh at every height (main's way)."""
    saved = body_measure.StandingBody.crossed
    body_measure.StandingBody.crossed = lambda body, z, rows=None: np.arange(len(body.faces)) if rows is None else rows
    try:
        yield
    finally:
        body_measure.StandingBody.crossed = saved


@contextmanager
def measured_as_before():
    """core.synthesis.extra_refine measuring with main's extra measurements (its landmarks too, for the
    deformations)."""
    saved = refine_extra.mannequin_extra_measurements, refine_extra.MannequinLandmarks
    refine_extra.mannequin_extra_measurements = mannequin_extra_measurements_before
    refine_extra.MannequinLandmarks = MannequinLandmarksBefore
    try:
        yield
    finally:
        refine_extra.mannequin_extra_measurements, refine_extra.MannequinLandmarks = saved


def run(quick=False):
    """``quick``: one RM and one synthesized mannequin per set, one meet_extra, one body, 3 population rows, each
    once (checks that it runs)."""
    repeat, meets = (1, 1) if quick else (3, MEET_PER_SET)
    print(f"{'mannequin':<28} {'before ms':>9} {'now ms':>7} {'ratio':>6} {'max |diff| cm':>13}")
    ratios, worst, sets = [], {}, {}
    for set_name in (FEMALE_SET, MALE_SET):
        reference = named_reference_set(set_name)
        grid = synthesized(reference, 243 if quick else GRID_STEP)
        sets[set_name] = grid
        for label, mannequins in (("RM", reference.mannequins[: 1 if quick else None]), ("synthesized", grid)):
            for mannequin in mannequins:
                before, old = best_time(lambda m=mannequin: mannequin_extra_measurements_before(m), repeat)
                now, new = best_time(lambda m=mannequin: mannequin_extra_measurements(m), repeat)
                difference = max(abs(new[key] - old[key]) for key in EXTRA_MEASUREMENTS)
                worst[(set_name, label)] = max(worst.get((set_name, label), 0.0), difference)
                ratios.append(before / now)
                print(
                    f"{set_name + ' ' + mannequin.name:<28} {1e3 * before:9.1f} {1e3 * now:7.1f} "
                    f"{before / now:6.1f} {difference:13.1e}"
                )
    print(
        f"mannequin_extra_measurements: median {statistics.median(ratios):.1f}x faster (min {min(ratios):.1f}x); "
        "largest difference: " + ", ".join(f"{s} {label} {d:.1e} cm" for (s, label), d in worst.items())
    )

    print(f"\nmeet_extra (each extra measurement asked at x {', '.join(f'{c:g}' for c in EXTRA_CHANGE)}):")
    print(f"{'mannequin':<28} {'before s':>8} {'now s':>6} {'ratio':>6} {'max |diff| cm':>13}  misses now")
    totals = [0.0, 0.0]
    for set_name, grid in sets.items():
        for mannequin in grid[:meets]:
            start = mannequin_extra_measurements(mannequin)
            extra = {key: start[key] * change for key, change in zip(EXTRA_MEASUREMENTS, EXTRA_CHANGE)}
            with measured_as_before():
                before, (_, old, _) = best_time(lambda m=mannequin, e=extra: refine_extra.meet_extra(m, e), repeat=1)
            now, (_, new, misses) = best_time(lambda m=mannequin, e=extra: refine_extra.meet_extra(m, e), repeat=1)
            totals[0] += before
            totals[1] += now
            difference = max(abs(new[key] - old[key]) for key in new)
            print(
                f"{set_name + ' ' + mannequin.name:<28} {before:8.2f} {now:6.2f} {before / now:6.1f} "
                f"{difference:13.1e}  {misses or 'none'}"
            )
    print(
        f"meet_extra: {totals[0] / totals[1]:.1f}x faster over {2 * meets} mannequins "
        f"({totals[0] / (2 * meets):.2f} s -> {totals[1] / (2 * meets):.2f} s per mannequin)"
    )

    bodies(BODIES[:1] if quick else BODIES, repeat=1 if quick else 2)
    population(3 if quick else 12)


def population(rows=12):
    """``population --extras --synthesize`` timed with main's extra measurements and with today's. Exit 3 (exact mode
    missed a row's extra measurement: the files are written) is a result to say, not a failure of the bench."""

    def once():
        with tempfile.TemporaryDirectory() as folder:
            folder = pathlib.Path(folder)
            start = time.perf_counter()
            code = ellimann(
                [
                    "population",
                    "--stats",
                    "ansur2_female",
                    "--n",
                    str(rows),
                    "--seed",
                    "1",
                    "-q",
                    "-o",
                    str(folder / "people.csv"),
                    "--extras",
                    "--synthesize",
                    str(folder / "out"),
                ]
            )
            assert code in (0, MISSED), code
            return time.perf_counter() - start, code

    with measured_as_before():
        before, before_code = once()
    now, now_code = once()
    print(
        f"\npopulation --n {rows} --extras --synthesize: before {before:.1f} s (exit {before_code}), now {now:.1f} s "
        f"(exit {now_code}; 3: exact mode missed a row, see its warning above), {before / now:.1f}x faster"
    )


def bodies(names=BODIES, repeat=2):
    print(
        f"\nmeasure_body_mesh:\n{'body':<17} {'triangles':>9} {'before s':>8} {'now s':>6} {'ratio':>6} "
        f"{'max |diff| cm':>13}"
    )
    totals = [0.0, 0.0]
    for name in names:
        mesh = read_obj(TRACING_FOLDER / f"{name}.obj", up="z")
        with every_triangle_cut():
            before, old = best_time(lambda m=mesh: body_measure.measure_body_mesh(m.vertices, m.faces), repeat=repeat)
        now, new = best_time(lambda m=mesh: body_measure.measure_body_mesh(m.vertices, m.faces), repeat=repeat)
        totals[0] += before
        totals[1] += now
        difference = max(abs(new.values[key] - old.values[key]) for key in old.values)
        print(f"{name:<17} {len(mesh.faces):9d} {before:8.2f} {now:6.2f} {before / now:6.1f} {difference:13.1e}")
    print(f"measure_body_mesh: {totals[0] / totals[1]:.1f}x faster over {len(names)} bodies")


if __name__ == "__main__":
    run()
