"""Give the shipped reference sets their body space (issue 43): the 80 bodies of a bank of ../shared/bodies and the
six bodies of the set's refmodels folder (its neutral body and the five its RMs were traced from: they hold the
corners of the ranges the bank leaves thin), measured (the eleven and core.measure.further's ten) and reduced to
a ridge body model's statistics (core.synthesis.body_space), written as the set's ``body_space.npz`` and named in
its manifest; nothing else in the set changes. The fine sets hold the same bodies as their coarse twins.

    .venv/bin/python -m tools.shipped.add_body_space            # write body_space.npz into the four shipped sets
    .venv/bin/python -m tools.shipped.add_body_space --check    # compare the shipped files with what it would write
"""

import argparse
import json
import pathlib
import sys
import time

import numpy as np

from ellimann_addon.core.files import atomic_write_text
from ellimann_addon.core.mannequin.joints import joints_from_makehuman
from ellimann_addon.core.synthesis.body_space import SPACE_FILE, read_body_space, space_from_meshes
from ellimann_addon.core.synthesis.manifest import MANIFEST_FILE, read_manifest

from .add_bodies import body_labels, meshes
from .reference_sets import BUILD_SETS, SHARED

BANKS = SHARED / "bodies"
# what --check lets a fresh file differ by: float16 directions (up to 0.66 m: a float16 step there is 4.9e-4, and
# rounding may land a step either side), float32 mean, measurements (cm), the Gram matrix (m^2)
TOLERANCES = {"mean": 1e-5, "directions": 1e-3, "measured": 2e-2, "gram": 1e-6}


def bank(sex, folder=BANKS):
    """(names, vertices (N, V, 3), faces, joints (N, 24, 3)) of ../shared/bodies/<sex>.npz."""
    with np.load(pathlib.Path(folder) / f"{sex}.npz") as data:
        labels = [str(b) for b in data["bone_labels"]]
        joints = np.stack([joints_from_makehuman(dict(zip(labels, j))) for j in data["joints"]])
        vertices, faces = data["vertices"].astype(float), data["faces"]
    return [f"bank_{i:02d}" for i in range(len(vertices))], vertices, faces, joints


def training_bodies(build_set):
    """(names, vertices, faces, joints): the set's six refmodels bodies, then its sex's bank."""
    six = [build_set.reference_body, "small_slim", "tall_slim", "small_chubby", "tall_chubby", "average"]
    vertices, faces, joints = meshes(build_set.refmodels, six)
    names, bank_vertices, bank_faces, bank_joints = bank(build_set.sex)
    if not np.array_equal(faces, bank_faces):
        raise SystemExit(f"{build_set.name}: the bank's faces are not the refmodels' (another topology)")
    return six + names, np.concatenate([vertices, bank_vertices]), faces, np.concatenate([joints, bank_joints])


def make_space(build_set, log=print):
    names, vertices, faces, joints = training_bodies(build_set)
    region, region_names, _ = body_labels()
    started = time.perf_counter()

    def progress(done, total, name):
        if done % 20 == 0 or done == total:
            log(f"  {build_set.name}: measured {done} of {total} ({time.perf_counter() - started:.0f} s)")

    return space_from_meshes(names, vertices, faces, region, region_names, joints, build_set.fractions, progress)


def add_body_space(build_set, space, log=print):
    """Write the set's body_space.npz and name it in its manifest (everything else as it was)."""
    path = space.save(build_set.out / SPACE_FILE)
    manifest = read_manifest(build_set.out)
    manifest.body_space = SPACE_FILE
    atomic_write_text(build_set.out / MANIFEST_FILE, json.dumps(manifest.to_dict(), indent=1) + "\n")
    log(f"{build_set.name}: {path.relative_to(build_set.out.parent)} ({path.stat().st_size:,} bytes)")
    return path


def check(build_set, fresh):
    """Problems (lines) of the set's shipped body space against ``fresh`` (empty: none)."""
    manifest = read_manifest(build_set.out)
    if manifest.body_space != SPACE_FILE or not (build_set.out / SPACE_FILE).is_file():
        return [f"{build_set.name}: no {SPACE_FILE} named in its manifest"]
    shipped = read_body_space(build_set.out / SPACE_FILE)
    if shipped.names != fresh.names or shipped.keys != fresh.keys:
        return [f"{build_set.name}: bodies or measurements differ"]
    problems = []
    for name, tolerance in TOLERANCES.items():
        diff = float(np.abs(np.asarray(getattr(shipped, name), float) - getattr(fresh, name)).max())
        if diff > tolerance:
            problems.append(f"{build_set.name}: {name} differs by up to {diff:.3g}")
    return problems


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.shipped.add_body_space", description=__doc__.split("\n")[0])
    parser.add_argument("--sets", default=",".join(BUILD_SETS), help=f"comma-separated, of {', '.join(BUILD_SETS)}")
    parser.add_argument("--check", action="store_true", help="compare with the shipped files; write nothing")
    args = parser.parse_args(argv)
    sets = [BUILD_SETS[name] for name in args.sets.split(",")]
    spaces = {}  # one space per sex: the fine sets hold their coarse twins' bodies
    problems = []
    for build_set in sets:
        if build_set.sex not in spaces:
            spaces[build_set.sex] = make_space(build_set, log=lambda line: print(line, file=sys.stderr))
        if args.check:
            problems += check(build_set, spaces[build_set.sex])
        else:
            add_body_space(build_set, spaces[build_set.sex])
    if args.check:
        print("\n".join(problems) or "the shipped body spaces are what tools.shipped.add_body_space writes")
        return 1 if problems else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
