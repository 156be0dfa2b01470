"""The posing shape check: real reference bodies re-posed to a T-pose by their own skeleton against the
synthesized mannequin in ``t_pose``, by voxel IoU, beside the same IoU at rest.

    .venv/bin/python -m tools.figures.pose_shape [--refmodels DIR] [--spacing M]

Each body of ``refmodels/`` (the five the Reference Mannequins are built from) is re-posed with rigid
per-vertex bones (each vertex rides on its dominant skinning bone of ``reference_female_regions.json``;
the shoulder01 vertices half way, a linear blend of the two transforms): the ``upperarm*`` vertices turn about
the body's ``upperarm01`` joint so the upper arm is horizontal, the ``lowerarm*``, wrist and hand ones then also
about ``lowerarm01`` so the forearm is horizontal, as ``core.pose.standard.t_pose`` poses the mannequin. The mannequin
is synthesized at the body's Table 2.3 measurements (its RM), posed with cushions (``core.pose.posed_pieces``). The body
is moved onto the mannequin by the mean offset between their torso joints (the registration of the build).
IoU = |body and mannequin| / |body or mannequin| over voxel centres (``--spacing``, default 6 mm).
"""

import argparse
import json
import pathlib

import numpy as np

from ellimann_addon.core.constants import REFERENCE_MEASUREMENTS
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.geometry.volume import BodyVolume
from ellimann_addon.core.mannequin.joints import joints_from_makehuman
from ellimann_addon.core.mannequin.skeleton import JOINT_INDEX
from ellimann_addon.core.pose.kinematics import rotation_between
from ellimann_addon.core.pose.posed_pieces import PosingRig, body_pieces, pieces_contain
from ellimann_addon.core.pose.standard import a_pose, t_pose
from ellimann_addon.core.synthesis.reference_set import load_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize_batch

from ..shipped.bodies import RM_BODIES, load_labels

DEFAULT_REFMODELS = pathlib.Path(__file__).resolve().parents[3] / "shared" / "refmodels"
TORSO = ("Pelvis", "Spine1", "Spine2", "Spine3", "Neck")
UPPER = ("upperarm",)
LOWER = ("lowerarm", "wrist", "metacarpal", "finger")


def t_posed_body(vertices, bones, heads):
    """The body's vertices with the arms turned horizontal about its own shoulder and elbow joints."""
    out = vertices.copy()
    for s, sign in (("L", 1.0), ("R", -1.0)):
        shoulder, elbow, wrist = (np.array(heads[f"{b}.{s}"]) for b in ("upperarm01", "lowerarm01", "wrist"))
        upper = rotation_between(elbow - shoulder, [sign, 0.0, 0.0])
        fore = upper @ rotation_between(wrist - elbow, elbow - shoulder)  # straight elbow, then the upper's turn
        elbow_posed = shoulder + upper @ (elbow - shoulder)
        side = np.char.endswith(bones, f".{s}")
        on_upper = side & np.array([b.startswith(UPPER) for b in bones])
        on_lower = side & np.array([b.startswith(LOWER) for b in bones])
        on_shoulder = side & np.char.startswith(bones, "shoulder01")
        out[on_upper] = shoulder + (vertices[on_upper] - shoulder) @ upper.T
        out[on_lower] = elbow_posed + (vertices[on_lower] - elbow) @ fore.T
        moved = shoulder + (vertices[on_shoulder] - shoulder) @ upper.T
        out[on_shoulder] = 0.5 * (vertices[on_shoulder] + moved)
    return out


def iou(body_vertices, faces, rig, pose, spacing):
    """Voxel IoU of a closed body mesh and the rig's mannequin in ``pose``."""
    grid = BodyVolume(body_vertices, faces).grid(spacing, margin=0.06)
    shape = grid.inside.shape
    axes = [grid.origin[k] + spacing * np.arange(shape[k]) for k in range(3)]
    centres = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    ellipsoids, meshes = body_pieces(rig.pose(pose))
    mannequin = np.zeros(len(centres), dtype=bool)
    for start in range(0, len(centres), 200_000):
        mannequin[start : start + 200_000] = pieces_contain(ellipsoids, meshes, centres[start : start + 200_000])
    body = grid.inside.ravel()
    # The grid spans the body with a margin: how far the mannequin reaches beyond it (uncounted), in metres.
    low = np.min(
        [v.min(axis=0) for v, _ in meshes] + [(ellipsoids[1] - ellipsoids[2].max(axis=1)[:, None]).min(0)], axis=0
    )
    high = np.max(
        [v.max(axis=0) for v, _ in meshes] + [(ellipsoids[1] + ellipsoids[2].max(axis=1)[:, None]).max(0)], axis=0
    )
    beyond = max(
        0.0,
        float(
            np.max(
                np.r_[
                    axes[0][0] - low[0],
                    axes[1][0] - low[1],
                    axes[2][0] - low[2],
                    high[0] - axes[0][-1],
                    high[1] - axes[1][-1],
                    high[2] - axes[2][-1],
                ]
            )
        ),
    )
    return float(np.sum(body & mannequin) / np.sum(body | mannequin)), beyond


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tools.figures.pose_shape", description=__doc__.splitlines()[0])
    parser.add_argument("--refmodels", type=pathlib.Path, default=DEFAULT_REFMODELS)
    parser.add_argument("--spacing", type=float, default=0.006)
    args = parser.parse_args(argv)
    skeleton = json.loads((args.refmodels / "skeleton.json").read_text(encoding="utf-8"))
    labels = load_labels(args.refmodels)
    reference = load_reference_set()
    print(f"voxel IoU, body vs synthesized mannequin with cushions ({args.spacing * 1e3:g} mm voxels)")
    print(f"{'body':14s} {'rest (A-pose)':>14s} {'T-pose':>8s} {'change':>8s}")
    for name in RM_BODIES:
        body = read_obj(args.refmodels / f"{name}.obj", up="z")
        heads = skeleton["bodies"][name]
        request = [REFERENCE_MEASUREMENTS[name][k] for k in ("He", "Sh", "Br", "Wa", "Hi")]
        mannequin = synthesize_batch(reference, [request]).mannequin(0)
        body_joints = joints_from_makehuman(heads)
        torso = [JOINT_INDEX[n] for n in TORSO]
        shift = (mannequin.joints[torso] - body_joints[torso]).mean(axis=0)
        rig = PosingRig(mannequin, subdivisions=3)
        rest, beyond_rest = iou(body.vertices + shift, body.faces, rig, a_pose(mannequin.joints), args.spacing)
        posed = t_posed_body(body.vertices, labels.bone, heads) + shift
        t, beyond_t = iou(posed, body.faces, rig, t_pose(mannequin.joints), args.spacing)
        beyond = max(beyond_rest, beyond_t)
        note = f"  (mannequin reaches up to {beyond * 1e3:.0f} mm beyond the grid, not counted)" if beyond else ""
        print(f"{name:14s} {rest:14.3f} {t:8.3f} {t - rest:+8.3f}{note}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
