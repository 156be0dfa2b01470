"""A synthetic set of five Reference Mannequins on the toy topology, for tests and benchmarks.

Stands in for the shipped ``reference_blends/`` until (and beside) the real RMs: five variants of one
small body, each shaped region by region (height, shoulders, chest, belly, pelvis and legs, with
rotations that change with the body too) until m_T meets its row of Table 2.3 within 0.01%, then
registered. Their ``measurements`` are the Table 2.3 targets, as for the real RMs. The shaping here
is deliberately independent of ``core.synthesis.synthesize``'s refinement.
"""

import pathlib

import numpy as np

from devkit.toy import TOY_PARTS, rotation_from_vector
from ellimann_addon.core.constants import REFERENCE_MEASUREMENTS
from ellimann_addon.core.geometry.ellipsoid import axis_extent
from ellimann_addon.core.geometry.frames import mirror_frame
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.topology import Topology
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.synthesize import REFERENCE_NAMES, ReferenceSet, load_reference_set

# Left and central parts of a ~1.6 m body: centre (m), rotation vector, semi-axes (m).
BASE_GEOMETRY = {
    "1.a Head": ((0.0, 0.0, 1.50), (0.1, 0.0, 0.0), (0.075, 0.095, 0.11)),
    "2.a Chest": ((0.0, 0.0, 1.16), (0.05, 0.0, 0.0), (0.15, 0.10, 0.09)),
    "2.b Belly": ((0.0, -0.01, 1.02), (0.0, 0.0, 0.0), (0.13, 0.095, 0.12)),
    "3.a Pelvis": ((0.0, 0.01, 0.82), (-0.1, 0.0, 0.0), (0.16, 0.11, 0.12)),
    "4.a Trapezius.L": ((0.11, 0.01, 1.27), (0.0, 0.3, 0.1), (0.09, 0.06, 0.08)),
    "5.a Arm.L": ((0.24, 0.02, 0.98), (0.0, 0.2, 0.0), (0.045, 0.045, 0.27)),
    "6.a Thigh.L": ((0.085, 0.0, 0.60), (0.0, 0.06, 0.0), (0.075, 0.075, 0.24)),
    "6.b Shin.L": ((0.095, 0.01, 0.20), (0.05, 0.02, 0.0), (0.05, 0.05, 0.20)),
}
REGION_OF_MEASUREMENT = {
    "Sh": ("4.a Trapezius",),
    "Br": ("2.a Chest",),
    "Wa": ("2.b Belly",),
    "Hi": ("3.a Pelvis", "6.a Thigh"),
}


def _normalised(me):
    """Where a request sits in L, 0..1 per measurement (drives the rotation changes)."""
    lows = {k: min(m[k] for m in REFERENCE_MEASUREMENTS.values()) for k in MEASUREMENTS}
    highs = {k: max(m[k] for m in REFERENCE_MEASUREMENTS.values()) for k in MEASUREMENTS}
    return {k: (me[k] - lows[k]) / (highs[k] - lows[k]) for k in MEASUREMENTS}


def shaped_body(me, factors):
    """The base body shaped by per-measurement factors (He, Sh, Br, Wa, Hi), as a symmetric Mannequin.

    He stretches vertically; Br, Wa scale their region horizontally; Hi scales pelvis and thighs
    horizontally and moves the legs out; Sh widens the trapezius and carries the arms outwards.
    Rotations depend on ``me`` (hips tilt the thighs, the belly and chest pitch with their girth).
    """
    t = _normalised(me)
    h, s, b, w, p = factors
    tilt = {
        "1.a Head": (0.1 - 0.05 * t["He"], 0.0, 0.0),
        "2.a Chest": (0.05 + 0.08 * t["Br"], 0.0, 0.0),
        "2.b Belly": (0.12 * t["Wa"], 0.0, 0.0),
        "3.a Pelvis": (-0.1 - 0.05 * t["Hi"], 0.0, 0.0),
        "4.a Trapezius.L": (0.0, 0.3, 0.1 + 0.05 * t["Sh"]),
        "5.a Arm.L": (0.0, 0.2 + 0.1 * t["Sh"], 0.0),
        "6.a Thigh.L": (0.0, 0.04 + 0.08 * t["Hi"], 0.0),
        "6.b Shin.L": (0.05, 0.02 - 0.03 * t["Hi"], 0.0),
    }
    topology = Topology(TOY_PARTS)
    n = len(topology)
    rotation, center, semi = np.zeros((n, 3, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    for name, (c, _, d) in BASE_GEOMETRY.items():
        i = topology.index[name]
        r = rotation_from_vector(tilt[name])
        c, d = np.array(c, float), np.array(d, float)
        vertical = r[2] ** 2
        c[2] *= h
        d = d * (1.0 + (h - 1.0) * vertical)
        horizontal = 1.0 - vertical
        for key, factor in (("Br", b), ("Wa", w), ("Hi", p)):
            if any(name.startswith(region) for region in REGION_OF_MEASUREMENT[key]):
                d = d * (1.0 + (factor - 1.0) * horizontal)
                c[0] *= factor
        if name.startswith("6.b Shin"):
            c[0] *= p
        if name.startswith("4.a Trapezius"):
            c[0] *= s
            d = d * (1.0 + (s - 1.0) * r[0] ** 2)
        if name.startswith("5.a Arm"):
            c[0] += (s - 1.0) * 0.2
        rotation[i], center[i], semi[i] = r, c, d
    left = topology.indices("L")
    right = topology.twin_indices[left]
    rotation[right], center[right] = mirror_frame(rotation[left], center[left], axis=0)
    semi[right] = semi[left]
    mannequin = Mannequin(topology, rotation, center, semi, role="reference")
    lowest = np.min(mannequin.center[:, 2] - axis_extent(mannequin.rotation, mannequin.semi_axes, 2))
    mannequin.center[:, 2] -= lowest
    return mannequin


def make_reference(name, tolerance=1e-4, iterations=60):
    """One synthetic RM meeting its Table 2.3 row within ``tolerance`` (relative) by m_T."""
    me = REFERENCE_MEASUREMENTS[name]
    target = np.array([me[k] for k in MEASUREMENTS])
    factors = np.ones(5)
    for _ in range(iterations):
        measured = np.array(list(shaped_body(me, factors).measure().values()))
        ratio = target / measured
        if np.max(np.abs(ratio - 1.0)) < tolerance:
            break
        factors *= ratio  # each factor drives its own measurement almost proportionally
    else:
        raise RuntimeError(f"synthetic RM {name} did not converge: {measured} vs {target}")
    body = shaped_body(me, factors)
    return body.copy(name=name, measurements=dict(me))


def make_reference_mannequins():
    return [make_reference(name) for name in REFERENCE_NAMES]


def make_reference_set():
    return ReferenceSet(make_reference_mannequins(), names=list(REFERENCE_NAMES))


def write_reference_folder(folder):
    """The synthetic RMs as ``<name>.json`` files (the layout of ``reference_blends/``)."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for mannequin in make_reference_mannequins():
        mannequin.save(folder / f"{mannequin.name}.json")
    return folder


def shipped_or_synthetic():
    """The shipped reference set when ``reference_blends/`` has it, else the synthetic one: (set, label)."""
    try:
        return load_reference_set(), "shipped reference_blends/"
    except Exception:  # noqa: BLE001 - any failure to load means: not shipped yet
        return make_reference_set(), "synthetic (devkit.synthetic, toy topology)"
