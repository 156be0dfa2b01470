"""Building a reference set of five bodies (``ellimann references build``'s core): where the time goes, and
the build fitting the bodies one at a time (before) against several processes at once (now), in the
same run, with the largest difference between the two results (the bodies are independent: none).

Needs ../shared/refmodels (the five Table 2.3 bodies) and the shipped Base Mannequin with its recorded
selections; says so and skips otherwise. Takes a few minutes.
"""

import os
import pathlib
import time

import numpy as np

from ellimann_addon.core.constants import REFERENCE_MEASUREMENTS
from ellimann_addon.core.fitting import mannequin_fit as body_fit
from ellimann_addon.core.fitting import reference_build
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

REFMODELS = pathlib.Path(__file__).resolve().parents[2] / "shared" / "refmodels"


class Stopwatch:
    """Seconds spent in wrapped functions, by label."""

    def __init__(self):
        self.seconds = {}

    def wrap(self, module, name, label):
        original = getattr(module, name)

        def timed(*args, **kwargs):
            started = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                self.seconds[label] = self.seconds.get(label, 0.0) + time.perf_counter() - started

        setattr(module, name, timed)
        return original


def run(quick=False):
    """``quick``: three bodies (a set's fewest), one process only (checks that it runs)."""
    names = list(REFERENCE_MEASUREMENTS)[: 3 if quick else None]
    targets = {name: REFERENCE_MEASUREMENTS[name] for name in names}
    paths = [REFMODELS / f"{name}.obj" for name in names]
    if not all(p.is_file() for p in paths):
        print(f"skipped: the bodies of {REFMODELS} are not there")
        return
    base = Mannequin.load(REFERENCE_FOLDER / "base_mannequin.json")
    started = time.perf_counter()
    bodies = [read_obj(p, up="z") for p in paths]  # the refmodels are in ElliMann's axes (Z up)
    read = time.perf_counter() - started

    watch = Stopwatch()
    originals = [
        (module, name, watch.wrap(module, name, label))
        for module, name, label in (
            (body_fit, "inscribed_ellipsoid", "inscribe parts"),
            (reference_build, "fit_mannequin", "fit bodies"),
            (reference_build, "adjust", "refine to targets"),
            (reference_build, "clean", "clean together"),
        )
    ]
    started = time.perf_counter()
    built = reference_build.build_reference_set(base, bodies, targets, workers=1)
    serial, report = built.mannequins, built.report
    one = time.perf_counter() - started
    for module, name, original in originals:
        setattr(module, name, original)

    fit = watch.seconds["fit bodies"]
    rows = [
        (f"read {len(bodies)} OBJ files", read),
        (f"fit {len(bodies)} bodies (core.fitting.mannequin_fit)", fit),
        ("  of which: inscribe each part (core.fitting.inscribed pattern search)", watch.seconds["inscribe parts"]),
        ("  of which: the rest (volume grid, normals, part covers)", fit - watch.seconds["inscribe parts"]),
        ("refine to targets (core.synthesis.refine)", watch.seconds["refine to targets"]),
        ("clean together", watch.seconds["clean together"]),
        ("check coverage (core.geometry.volume, 5 mm grid)", report.seconds.get("coverage check", 0.0)),
    ]
    print(f"{len(bodies)}-body build, one process: {one:.1f} s")
    for label, seconds in rows:
        print(f"  {label:64s} {seconds:7.1f} s  {seconds / one:6.1%}")
    if quick:
        return serial

    workers = max(2, min(len(bodies), os.cpu_count() or 1))
    started = time.perf_counter()
    parallel = reference_build.build_reference_set(base, bodies, targets, workers=workers).mannequins
    many = time.perf_counter() - started
    diff = max(
        float(np.abs(getattr(serial[n], a) - getattr(parallel[n], a)).max())
        for n in names
        for a in ("rotation", "center", "semi_axes")
    )
    print(
        f"five-body build, {workers} processes: {many:.1f} s ({one / many:.2f}x faster on {os.cpu_count()} CPUs; "
        f"largest difference from the one-process build {diff:.1g} m)"
    )
