"""Give the shipped reference sets their bodies: each set's five RM bodies (tools/shipped/reference_sets.py knows which
folder of ../shared holds them), their region labels and the body model's bone weights
(../shared/refmodels/reference_female_regions.json and skin_weights.npz, one topology for the female and the male
bodies), written as the set's ``bodies.npz`` (core.body.bodies) and named in its manifest; nothing else in the
set changes.

    .venv/bin/python -m tools.shipped.add_bodies            # write bodies.npz into the four shipped sets
    .venv/bin/python -m tools.shipped.add_bodies --check    # compare the shipped files with what it would write
"""

import argparse
import json
import pathlib
import sys

import numpy as np

from ellimann_addon.core.files import atomic_write_text
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.synthesis.bodies import BODIES_FILE, BodyLabels, from_meshes, read_bodies
from ellimann_addon.core.synthesis.manifest import MANIFEST_FILE, read_manifest

from .bodies import LABELS_FILE, load_skeletons
from .reference_sets import BUILD_SETS, TRACING_FOLDER

WEIGHTS_FILE = "skin_weights.npz"
# what --check lets a fresh file differ by: float16 offsets (m) and weights, float32 measurements (cm)
TOLERANCES = {"mean": 1e-4, "offsets": 1e-4, "joints": 1e-4, "joint_weight": 1e-3, "measured": 1e-2}


def body_labels(folder=TRACING_FOLDER):
    """(region (V,), region names, (bone indices, bone weights, bone labels)) of the shared topology."""
    data = json.loads((pathlib.Path(folder) / LABELS_FILE).read_text(encoding="utf-8"))
    with np.load(pathlib.Path(folder) / WEIGHTS_FILE) as weights:
        bones = (weights["vertex_bone_indices"], weights["vertex_bone_weights"], weights["bone_labels"])
    return np.array(data["labels"]), list(data["region_names"]), bones


def shipped_body_labels():
    """The shared topology's BodyLabels (core.synthesis.bodies), as the builders keep the bodies with."""
    return BodyLabels(*body_labels())


def meshes(folder, names):
    """(vertices (N, V, 3), faces, joints (N, 24, 3)) of the bodies ``names`` of a refmodels folder."""
    skeletons = load_skeletons(folder)
    read = [read_obj(pathlib.Path(folder) / f"{name}.obj", up="z") for name in names]
    faces = read[0].faces
    return np.stack([body.vertices for body in read]), faces, np.stack([skeletons[name] for name in names])


def set_bodies(build_set, names=None):
    """SetBodies of a shipped set: its RMs' bodies in the manifest's order (or ``names`` of its refmodels)."""
    names = names or read_manifest(build_set.out).mannequins
    vertices, faces, joints = meshes(build_set.refmodels, names)
    region, region_names, bones = body_labels()
    return from_meshes(names, vertices, faces, region, region_names, bones, joints, build_set.fractions)


def add_bodies(build_set, log=print):
    """Write the set's bodies.npz and name it in its manifest (everything else as it was)."""
    bodies = set_bodies(build_set)
    path = bodies.save(build_set.out / BODIES_FILE)
    manifest = read_manifest(build_set.out)
    manifest.bodies = BODIES_FILE
    atomic_write_text(build_set.out / MANIFEST_FILE, json.dumps(manifest.to_dict(), indent=1) + "\n")
    log(f"{build_set.name}: {path.relative_to(build_set.out.parent)} ({path.stat().st_size:,} bytes)")
    return path


def check(build_set):
    """Problems (lines) of the set's shipped bodies against a fresh make (empty: none)."""
    manifest = read_manifest(build_set.out)
    if manifest.bodies != BODIES_FILE or not (build_set.out / BODIES_FILE).is_file():
        return [f"{build_set.name}: no {BODIES_FILE} named in its manifest"]
    shipped, fresh = read_bodies(build_set.out / BODIES_FILE), set_bodies(build_set)
    problems = []
    if shipped.names != fresh.names or not np.array_equal(shipped.faces, fresh.faces):
        problems.append(f"{build_set.name}: bodies or faces differ")
    for name, tolerance in TOLERANCES.items():
        diff = float(np.nanmax(np.abs(getattr(shipped, name) - getattr(fresh, name))))
        if diff > tolerance:
            problems.append(f"{build_set.name}: {name} differs by up to {diff:.3g}")
    return problems


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.shipped.add_bodies", description=__doc__.split("\n")[0])
    parser.add_argument("--sets", default=",".join(BUILD_SETS), help=f"comma-separated, of {', '.join(BUILD_SETS)}")
    parser.add_argument("--check", action="store_true", help="compare with the shipped files; write nothing")
    args = parser.parse_args(argv)
    sets = [BUILD_SETS[name] for name in args.sets.split(",")]
    if args.check:
        problems = [line for build_set in sets for line in check(build_set)]
        print("\n".join(problems) or "the shipped bodies are what tools.shipped.add_bodies writes")
        return 1 if problems else 0
    for build_set in sets:
        add_bodies(build_set)
    return 0


if __name__ == "__main__":
    sys.exit(main())
