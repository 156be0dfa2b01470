"""A body space from many bodies (issue 43): IDW against ridge regression over the 86 bodies of each shipped set's
body space (its six refmodels bodies and its bank's 80), leave-one-out: each body's twin from the other 85 (the
space rebuilt without it, its regularisation cross-validated on those 85 alone), given five, eleven or all
twenty-one of its measurements, exactly or through a tape with noise, then the exact correction of the five
(core.body.correct, the body skin's). Voxel IoU at 8 mm and the per-vertex error (mean, and by region: the twin
shares the body's topology), both meshes stood on the body's floor with their volume centroids above its
(bench.bench_body_skin's rules); beside them what each measurement adds to the five (the model's own prediction,
no correction), and the speed of the body models.

    python -m bench.bench_body_space                      # both sets, every body
    python -m bench.bench_body_space --step 4 --sets female --draws 1
"""

import argparse
import statistics
import time

import numpy as np

from ellimann_addon.core.body.correct import BodySkinError
from ellimann_addon.core.body.model import IdwBodyModel
from ellimann_addon.core.body.ridge import EXACT, RidgeBodyModel
from ellimann_addon.core.body.skin import BodySkinMaker
from ellimann_addon.core.geometry.volume import IOU_MARGIN, BodyVolume, mesh_voxel_iou
from ellimann_addon.core.measurements import ALL_MEASUREMENTS, MEASUREMENTS
from ellimann_addon.core.synthesis.bodies import SetBodies, load_set_bodies
from ellimann_addon.core.synthesis.body_space import SPACE_MEASUREMENTS, read_body_space, space_from_arrays
from ellimann_addon.core.synthesis.shipped import reference_folder
from tools.shipped.add_body_space import training_bodies
from tools.shipped.reference_sets import BUILD_SETS

from .bench_body_skin import SPACING, stood

ELEVEN = ALL_MEASUREMENTS
REGIONS = {
    "head": ("head", "neck"),
    "chest": ("chest",),
    "belly": ("abdomen",),
    "pelvis": ("pelvis",),
    "thighs": ("thigh_L", "thigh_R"),
    "legs": ("shin_L", "shin_R", "foot_L", "foot_R"),
    "arms": tuple(f"{p}_{s}" for p in ("upper_arm", "forearm", "hand") for s in "LR"),
}
LENGTHS = ("He", "Sh", "crotch_height", "arm_length", "bust_depth", "waist_depth", "hip_depth", "bust_height")
LENGTHS += ("shoulder_to_wrist",)
TAPE_CM = {key: 0.5 if key in LENGTHS else 1.0 for key in SPACE_MEASUREMENTS}  # a real tape's error (sd)
SHIPPED_FIVE = ("small_slim", "tall_slim", "small_chubby", "tall_chubby", "average")

# (label, model, inputs, tolerances, noise on: None / "all" / "extras")
CONFIGS = (
    ("IDW over the set's five bodies (today)", "idw5", MEASUREMENTS, None, None),
    ("IDW over 85 bodies", "idw", MEASUREMENTS, None, None),
    ("ridge, five", "ridge", MEASUREMENTS, EXACT, None),
    ("ridge, eleven", "ridge", ELEVEN, EXACT, None),
    ("ridge, all 21", "ridge", SPACE_MEASUREMENTS, EXACT, None),
    ("ridge, eleven, fit for ISO tolerances", "ridge", ELEVEN, None, None),
    ("tape noise: ridge, five", "ridge", MEASUREMENTS, None, "all"),
    ("tape noise: ridge, eleven, fit exact", "ridge", ELEVEN, EXACT, "all"),
    ("tape noise: ridge, eleven, ISO tolerances", "ridge", ELEVEN, None, "all"),
    ("tape noise: ridge, all 21, ISO tolerances", "ridge", SPACE_MEASUREMENTS, None, "all"),
    ("extras' noise: ridge, eleven, fit exact", "ridge", ELEVEN, EXACT, "extras"),
    ("extras' noise: ridge, eleven, ISO tolerances", "ridge", ELEVEN, None, "extras"),
)


class Bank:
    """The 86 bodies of a shipped set's body space, in full (from ../shared), with the set's labels and weights."""

    def __init__(self, name):
        folder = reference_folder(name)
        self.space = read_body_space(folder / "body_space.npz")
        shipped = load_set_bodies(folder)
        names, vertices, faces, joints = training_bodies(BUILD_SETS[name])
        assert names == self.space.names, "the shipped body space holds other bodies: run tools.shipped.add_body_space"
        self.names, self.vertices, self.joints = names, vertices, joints
        mean = vertices.mean(axis=0)
        eleven = self.space.measured[:, : len(ELEVEN)]
        self.bodies = SetBodies(
            names, mean, vertices - mean, faces, shipped.region, shipped.region_names, shipped.joint_index,
            shipped.joint_weight, joints, eleven, shipped.fractions,
        )  # fmt: skip
        region_names = list(shipped.region_names)
        self.regions = {
            key: np.isin(shipped.region, [region_names.index(n) for n in names]) for key, names in REGIONS.items()
        }

    def __len__(self):
        return len(self.names)

    def without(self, i):
        keep = [k for k in range(len(self)) if k != i]
        space = space_from_arrays(
            [self.names[k] for k in keep], self.vertices[keep], self.joints[keep], self.space.measured[keep],
            self.space.fractions,
        )  # fmt: skip
        return keep, space

    def measured(self, i):
        return dict(zip(self.space.keys, self.space.measured[i].tolist()))


def scores(bank, i, vertices, grid=None):
    """{iou, error, <region>: mean mm} of a twin's ``vertices`` against body i."""
    body, faces = bank.vertices[i], bank.bodies.faces
    twin = stood(vertices, faces, body, faces)
    distance = np.linalg.norm(twin - body, axis=1) * 1e3
    out = {"error": float(distance.mean())}
    out.update({key: float(distance[mask].mean()) for key, mask in bank.regions.items()})
    if grid is not None:
        out["iou"] = mesh_voxel_iou(twin, faces, grid)
    return out


def noisy(request, on, rng):
    if on is None:
        return dict(request)
    return {
        key: value + (rng.standard_normal() * TAPE_CM[key] if on == "all" or key not in MEASUREMENTS else 0.0)
        for key, value in request.items()
    }


def twin_rows(bank, step=1, draws=1, configs=CONFIGS, seed=43):
    """{label: [scores per held-out body and draw]} and refusals {label: [lines]}."""
    rows = {label: [] for label, *_ in configs}
    refused = {label: [] for label, *_ in configs}
    rng = np.random.default_rng(seed)
    six = [bank.names.index(n) for n in bank.names[:6]]
    for i in range(0, len(bank), step):
        keep, space = bank.without(i)
        others = bank.bodies.subset(keep)
        grid = BodyVolume(bank.vertices[i], bank.bodies.faces).grid(SPACING, margin=IOU_MARGIN)
        five_bodies = [k for k in six if k != i and bank.names[k] in SHIPPED_FIVE]
        if len(five_bodies) < 5:  # a shipped body held out: the other five of the six
            five_bodies = [k for k in six if k != i]
        models = {
            "idw": IdwBodyModel(others),
            "idw5": IdwBodyModel(bank.bodies.subset(five_bodies)),
            EXACT: RidgeBodyModel(space, EXACT),
            None: RidgeBodyModel(space),
        }
        makers = {key: BodySkinMaker(others, model) for key, model in models.items()}
        truth = bank.measured(i)
        for label, model, inputs, tolerances, noise in configs:
            for _ in range(draws if noise else 1):
                request = noisy({key: truth[key] for key in inputs}, noise, rng)
                maker = makers[model if model != "ridge" else tolerances]
                five = {key: request[key] for key in MEASUREMENTS}
                shape = {key: request[key] for key in inputs if key not in MEASUREMENTS}
                try:
                    skin = maker.make(five, shape=shape or None)
                except BodySkinError as error:
                    refused[label].append(f"{bank.names[i]}: {error}")
                    continue
                row = scores(bank, i, skin.vertices, grid)
                row["blend"] = scores(bank, i, maker.interpolated(five | shape)[0])["error"]
                rows[label].append(row)
    return rows, refused


def adds(bank, step=1):
    """Each measurement added to the five alone, and greedily one after another: the mean per-vertex error (mm) of
    the ridge's own prediction (exact inputs, no correction), leave-one-out."""
    candidates = [key for key in SPACE_MEASUREMENTS if key not in MEASUREMENTS]
    held = list(range(0, len(bank), step))
    spaces = {i: RidgeBodyModel(bank.without(i)[1], EXACT) for i in held}

    def error(keys):
        values = []
        for i in held:
            truth = bank.measured(i)
            vertices = spaces[i].body({key: truth[key] for key in keys})[0]
            values.append(scores(bank, i, vertices)["error"])
        return statistics.mean(values)

    alone = {key: error(MEASUREMENTS + (key,)) for key in candidates}
    chosen, order = list(MEASUREMENTS), [("the five", error(MEASUREMENTS))]
    rest = list(candidates)
    while rest:
        trial = {key: error(tuple(chosen + [key])) for key in rest}
        key = min(rest, key=lambda k: (trial[k], rest.index(k)))
        chosen.append(key)
        rest.remove(key)
        order.append((key, trial[key]))
    return alone, order


def speed(bank, repeats=200):
    """Milliseconds per body of each model (the ridge's fit for a new set of inputs apart) and of the correction."""
    keep, space = bank.without(0)
    others = bank.bodies.subset(keep)
    truth = bank.measured(0)
    five = {key: truth[key] for key in MEASUREMENTS}
    eleven = {key: truth[key] for key in ELEVEN}
    idw, ridge = IdwBodyModel(others), RidgeBodyModel(space)
    started = time.perf_counter()
    ridge.fit(tuple(ELEVEN))
    first = time.perf_counter() - started
    out = {"ridge's fit for a new set of inputs": first}
    for label, model, request in (("IDW body", idw, five), ("ridge body (eleven)", ridge, eleven)):
        started = time.perf_counter()
        for _ in range(repeats):
            model.body(request)
        out[label] = (time.perf_counter() - started) / repeats
    maker = BodySkinMaker(others, ridge)
    started = time.perf_counter()
    for _ in range(5):
        maker.make(five, shape={key: truth[key] for key in ELEVEN if key not in MEASUREMENTS})
    out["body skin (ridge of eleven + correction of the five)"] = (time.perf_counter() - started) / 5
    return out


def table(rows, refused):
    regions = list(REGIONS)
    lines = [
        "| interpolation | made | mean IoU (min) | per vertex mm | " + " | ".join(regions) + " | model alone mm |",
        "|---" * (5 + len(regions)) + "|",
    ]
    for label, found in rows.items():
        if not found:
            continue
        iou = [r["iou"] for r in found]
        cells = [f"{statistics.mean(r[key] for r in found):.1f}" for key in regions]
        lines.append(
            f"| {label} | {len(found)} of {len(found) + len(refused[label])} | {statistics.mean(iou):.3f} "
            f"({min(iou):.3f}) | {statistics.mean(r['error'] for r in found):.2f} | " + " | ".join(cells) + " | "
            f"{statistics.mean(r['blend'] for r in found):.2f} |"
        )
    return "\n".join(lines)


def run(sets=("female", "male"), step=1, draws=1, with_adds=True, quick=False):
    """``quick``: the female set, every 40th body held out, without what each measurement adds (that it runs, not
    its figures)."""
    if quick:
        sets, step, with_adds = ("female",), 40, False
    for name in sets:
        bank = Bank(name)
        print(f"### {name}: leave-one-out over {len(range(0, len(bank), step))} of the {len(bank)} bodies")
        started = time.perf_counter()
        rows, refused = twin_rows(bank, step, draws)
        print(table(rows, refused))
        for label, lines in refused.items():
            for line in lines:
                print(f"  refused ({label}): {line}")
        print(f"({time.perf_counter() - started:.0f} s)")
        if with_adds:
            alone, order = adds(bank, step)
            five = order[0][1]
            print(f"\nwhat each measurement adds to the five ({five:.2f} mm, the model alone):")
            print("| measurement | with the five alone mm | added in turn (greedy) | mm |\n|---|---|---|---|")
            for (key, value), (greedy, after) in zip(sorted(alone.items(), key=lambda kv: kv[1]), order[1:]):
                print(f"| {key} | {value:.2f} | +{greedy} | {after:.2f} |")
        times = speed(bank)
        idw = times["IDW body"]
        print("\nspeed (ms; ratio to the IDW body):")
        for label, seconds in times.items():
            print(f"- {label}: {seconds * 1e3:.2f} ms ({seconds / idw:.2f}x)")
        print()


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m bench.bench_body_space", description=__doc__.split("\n")[0])
    parser.add_argument("--sets", default="female,male")
    parser.add_argument("--step", type=int, default=1, help="every n-th body held out")
    parser.add_argument("--draws", type=int, default=1, help="tape-noise draws per held-out body")
    parser.add_argument("--no-adds", action="store_true", help="without what each measurement adds")
    args = parser.parse_args(argv)
    run(args.sets.split(","), args.step, args.draws, not args.no_adds)


if __name__ == "__main__":
    main()
