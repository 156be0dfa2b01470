"""The posed skin's quality and the bone weights' cost, now against the weights before (the pieces' weights summed
per bone: ``devkit.skin_weights_before``), on every Reference Mannequin of both shipped sets at the preview level.

Per mannequin: the skin's signed volume change from rest in t_pose, attention, sit and over the walk's frames (the
smallest and the largest), the largest stretch of an edge over the walk (posed length over rest length, edges of at
least half a voxel), now and before; and the CPU time of the bone weights now and before (``Skin.bones()``, made once
per skin). Issue 26 asks for every standard pose and walk frame within 3% of rest.

``python -m bench.bench_skin_posing``
"""

import time

import numpy as np

from devkit.skin_weights_before import bone_weights_before
from ellimann_addon.core.geometry.mesh import directed_edges, volume
from ellimann_addon.core.mannequin.skin_record import SkinSettings
from ellimann_addon.core.pose.kinematics import bone_matrices
from ellimann_addon.core.pose.motion import clamped_motion
from ellimann_addon.core.skin.skinning import skinning_weights
from ellimann_addon.core.skin.surface import build_skin
from ellimann_addon.core.skin.weights import follow_pieces
from ellimann_addon.core.synthesis.shipped import named_reference_set

STILL = ("t_pose", "attention", "sit")


def quality(skin, bones, weights):
    """({pose: volume change}, walk (smallest, largest) volume change, the walk's largest edge stretch)."""
    joints, rest = skin.mannequin.joints, skin.volume
    edges = directed_edges(skin.faces)
    edges = edges[edges[:, 0] < edges[:, 1]]
    length = np.linalg.norm(skin.vertices[edges[:, 0]] - skin.vertices[edges[:, 1]], axis=1)
    real = length >= 0.5 * skin.settings.voxel

    def posed(pose):
        return follow_pieces(skin.vertices, bones, weights, bone_matrices(joints, pose)[:, :3, :])

    still = {name: volume(posed(clamped_motion(name, joints)[0][0]), skin.faces) / rest - 1.0 for name in STILL}
    walk, stretch = [], 0.0
    for pose in clamped_motion("walk", joints)[0]:
        moved = posed(pose)
        walk.append(volume(moved, skin.faces) / rest - 1.0)
        posed_length = np.linalg.norm(moved[edges[:, 0]] - moved[edges[:, 1]], axis=1)
        stretch = max(stretch, float((posed_length[real] / length[real]).max()))
    return still, (min(walk), max(walk)), stretch


def cpu(function):
    start = time.process_time()
    out = function()
    return out, time.process_time() - start


def run(quick=False):
    """``quick``: one mannequin of the female set (checks that it runs)."""
    settings = SkinSettings.at_level("preview")
    print(f"Posed skin volume change from rest (%) and the walk's largest edge stretch, {settings.voxel_mm:g} mm skins")
    print(
        f"  {'set':<7}{'mannequin':<14}{'':>7}{'t_pose':>8}{'attent.':>8}{'sit':>8}{'walk min':>9}{'walk max':>9}"
        f"{'stretch':>9}{'weights CPU':>13}"
    )
    worst = {"now": 0.0, "before": 0.0}
    for set_name in ("female",) if quick else ("female", "male"):
        for mannequin in named_reference_set(set_name).mannequins[: 1 if quick else None]:
            skin = build_skin(mannequin, settings)
            now = cpu(lambda s=skin: skinning_weights(s.vertices, s.faces, s.pieces, s.weights, s.mannequin))
            before = cpu(lambda s=skin: bone_weights_before(s))
            for label, ((bones, weights), seconds) in (("now", now), ("before", before)):
                still, walk, stretch = quality(skin, bones, weights)
                values = [still[name] for name in STILL] + list(walk)
                worst[label] = max(worst[label], max(abs(v) for v in values))
                print(
                    f"  {set_name:<7}{mannequin.name:<14}{label:>7}"
                    + "".join(f"{100 * v:+8.2f}" for v in values[:3])
                    + "".join(f"{100 * v:+9.2f}" for v in values[3:])
                    + f"{stretch:9.2f}{seconds * 1e3:10.0f} ms"
                )
    print(
        f"  largest |volume change| over every pose and set: now {100 * worst['now']:.2f}%, "
        f"before {100 * worst['before']:.2f}%"
    )


if __name__ == "__main__":
    run()
