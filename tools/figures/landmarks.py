"""Where a set's section heights fall on its bodies: the landmarks behind SECTION_FRACTIONS, measured.

    .venv/bin/python -m tools.figures.landmarks [--picture docs/images/landmarks.png]

For each body of the female and male sets (tools/shipped/reference_sets.py), as fractions of its height He: the
natural waist (the narrowest torso girth between 0.55 and 0.72 He; girths over the torso-mask triangles,
convex hull perimeters, as the bodies' READMEs measure), the crotch (the lowest pelvis vertex on the
sagittal plane), the most posterior buttock point, the bust point (the most anterior chest vertex off the
midline) and the shoulder joint centre (the skeleton's upperarm01). With ``--picture`` (needs matplotlib):
each body's torso girth against height, the set's section heights drawn across; below the crotch the torso
mask's section takes in both thighs.
"""

import argparse
import json
import sys

import numpy as np

from ellimann_addon.core.constants import CM_PER_M
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry.mesh import convex_hull_2d, plane_section_points, polygon_perimeter

from ..shipped.bodies import RM_BODIES, load_labels
from ..shipped.reference_sets import BUILD_SETS, TRACING_FOLDER

PROFILE = np.arange(0.40, 0.8201, 0.0025)  # fractions of He the girth profile is sampled at
WAIST_BAND = (0.55, 0.72)
LANDMARKS = ("natural waist", "crotch", "buttock", "bust point", "shoulder joint")


def girth_profile(body, labels, fractions=PROFILE):
    """Torso girth (cm) at each fraction of the body's height."""
    vertices, faces = body.vertices, body.faces
    floor, height = vertices[:, 2].min(), np.ptp(vertices[:, 2])
    torso = faces[labels.torso[faces].all(axis=1)]
    out = []
    for fraction in fractions:
        points = plane_section_points(vertices, torso, floor + fraction * height)
        out.append(polygon_perimeter(convex_hull_2d(points)) * CM_PER_M if len(points) >= 3 else 0.0)
    return np.array(out)


def landmarks(body, labels, joints):
    """{landmark: fraction of He} of one body (see the module's docstring)."""
    vertices = body.vertices
    floor, height = vertices[:, 2].min(), np.ptp(vertices[:, 2])

    def fraction(z):
        return float((z - floor) / height)

    profile = girth_profile(body, labels)
    band = (PROFILE >= WAIST_BAND[0]) & (PROFILE <= WAIST_BAND[1])
    waist = float(PROFILE[band][np.argmin(profile[band])])
    pelvis = labels.region == "pelvis"
    midline = pelvis & (np.abs(vertices[:, 0]) < 0.005)
    crotch = fraction(vertices[midline, 2].min())
    chest = (labels.region == "chest") & (np.abs(vertices[:, 0]) > 0.04)
    return {
        "natural waist": waist,
        "crotch": crotch,
        "buttock": fraction(vertices[pelvis][np.argmax(vertices[pelvis, 1]), 2]),
        "bust point": fraction(vertices[chest][np.argmin(vertices[chest, 1]), 2]),
        "shoulder joint": fraction(joints["upperarm01.L"][2]),
    }


def set_landmarks(build_set):
    labels = load_labels(TRACING_FOLDER)
    with open(build_set.refmodels / "skeleton.json", encoding="utf-8") as stream:
        skeleton = json.load(stream)["bodies"]
    out = {}
    for name in (build_set.reference_body, *RM_BODIES):
        body = read_obj(build_set.refmodels / f"{name}.obj", up="z")
        out[name] = (landmarks(body, labels, skeleton[name]), girth_profile(body, labels))
    return out


def picture(results, path):
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot

    figure, axes = pyplot.subplots(1, len(results), figsize=(6 * len(results), 7), sharey=True)
    for axis, (set_name, bodies) in zip(np.atleast_1d(axes), results.items()):
        for name, (_, profile) in bodies.items():
            axis.plot(profile, PROFILE, label=name, linewidth=2.5 if name.startswith("reference") else 1.2)
        for key, value in BUILD_SETS[set_name].fractions.items():
            if key != "Sh":
                axis.axhline(value, color="black", linestyle="--", linewidth=0.8)
                axis.text(axis.get_xlim()[0], value + 0.003, f"{key} {value:g}")
        axis.set_title(f"{set_name}: torso girth against height")
        axis.set_xlabel("torso girth (cm)")
        axis.legend(loc="lower right")
    np.atleast_1d(axes)[0].set_ylabel("height (fraction of He)")
    figure.tight_layout()
    figure.savefig(path, dpi=80)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.figures.landmarks", description=__doc__.split("\n")[0])
    parser.add_argument("--picture", help="also draw the girth profiles to this PNG (needs matplotlib)")
    args = parser.parse_args(argv)
    results = {name: set_landmarks(BUILD_SETS[name]) for name in ("female", "male")}
    print("| set | body | " + " | ".join(LANDMARKS) + " |")
    print("|---|---|" + "---|" * len(LANDMARKS))
    for set_name, bodies in results.items():
        for name, (found, _) in bodies.items():
            print(f"| {set_name} | {name} | " + " | ".join(f"{found[key]:.3f}" for key in LANDMARKS) + " |")
    if args.picture:
        picture(results, args.picture)
        print(f"wrote {args.picture}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
