"""A tube dress on a walking body: the convex mannequin and its skin against the dense body mesh skinned to the
same motion.

The Average Reference Mannequin walks (``core.pose.standard`` walk, after ``services.drape_motion.SETTLE_FRAMES``
frames turning from rest into its first frame) with the dress draped on (a) its convex pieces (cushions
and the ellipsoids not in one, the drape's default resolution), each bound rigidly to its bone, (b) its skin
at the drape's default level (one mesh, bound by the skin's own bone weights), and (c)
the dense body it stands for (``../shared/refmodels/average.obj``, 26,692 triangles), every vertex
weighted fully to the SMPL bone of its body-model bone (``reference_female_regions.json``'s per-vertex
skinning bone, mapped up MakeHuman's skeleton to the first bone the MakeHuman name map knows). Both run
the same armature, motion, garment and cloth settings in one process. Printed: seconds per simulated
frame (wall clock, mean of the frames), collider triangles, and each final dress against the dense body
posed at the last frame (signed distances; vertices inside it).
"""

import json
import os
import pathlib
import tempfile
import time

import numpy as np

from ellimann_addon.core.drape import garments
from ellimann_addon.core.drape.colliders import collision_pieces, skin_collider, skin_distance, triangle_count
from ellimann_addon.core.drape.fit_metrics import BodyPieces, fit_statistics, mesh_distance
from ellimann_addon.core.fitting.body_mesh import read_obj
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.skeleton import JOINT_NAMES
from ellimann_addon.core.pose.motion import clamped_motion
from ellimann_addon.core.pose.rig_names import RIG_NAME_MAPS
from ellimann_addon.core.synthesis.synthesize import REFERENCE_FOLDER

ROOT = pathlib.Path(__file__).resolve().parents[1]
REFMODELS = ROOT.parent / "shared" / "refmodels"
BODY = "average"
FRAMES = 48  # 12 settling into the walk, then 36 walking (a stride and a half)
EDGE = 0.025  # m


def run(frames=FRAMES, quick=False):
    """``quick``: 6 frames (checks that it runs)."""
    frames = 6 if quick else frames
    source = REFERENCE_FOLDER / f"{BODY}.json"
    paths = [REFMODELS / f"{BODY}.obj", REFMODELS / "skeleton.json", REFMODELS / "reference_female_regions.json"]
    if not source.is_file() or not all(p.is_file() for p in paths):
        print(f"skipped: needs {source} and {', '.join(str(p) for p in paths)}")
        return
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="ellimann-bench-"))
    import ellimann_addon

    ellimann_addon.register()
    try:
        mannequin = Mannequin.load(source)
        body = read_obj(paths[0], up="z")  # the refmodels' bodies are in ElliMann's axes (Z up)
        vertices, faces = body.vertices, body.faces
        compare(mannequin, vertices, faces, dense_bones(paths[1], paths[2]), frames)
    finally:
        ellimann_addon.unregister()


def dense_bones(skeleton_path, regions_path):
    """(V,) SMPL joint index of each dense-body vertex."""
    skeleton = json.loads(skeleton_path.read_text())
    parents = dict(zip(skeleton["bones"], skeleton["parents"]))
    regions = json.loads(regions_path.read_text())
    known = RIG_NAME_MAPS["makehuman"]

    def joint(bone):
        while bone is not None and bone not in known:
            bone = parents[bone]
        return JOINT_NAMES.index(known[bone]) if bone is not None else 0

    per_bone = np.array([joint(name) for name in regions["bone_names"]])
    return per_bone[np.asarray(regions["bone_labels"], dtype=int)]


def compare(mannequin, body_vertices, body_faces, bones, frames):
    import bpy

    from ellimann_addon.blender.services import drape
    from ellimann_addon.blender.services.chatter import blender_output
    from ellimann_addon.blender.services.drape_motion import animate_drape, body_motion, settle_frames
    from ellimann_addon.blender.services.rig import bake_action, bare_armature, bind_weights
    from ellimann_addon.blender.services.scene import empty_scene

    walk, _, _ = clamped_motion("walk", mannequin.joints)
    motion = body_motion(walk, frames, True)
    settings = drape.DrapeSettings(frames=frames, edge=EDGE)
    exact = BodyPieces(mannequin, cushions=True, subdivisions=4)
    skin, skin_piece = skin_collider(mannequin, settings.skin_level)
    to_skin = skin_distance(skin)
    garment = garments.make_garment(mannequin, "tube_dress", edge=EDGE)
    garment = garments.clear_of(
        garment,
        lambda p: np.minimum.reduce(
            [exact.signed_distance(p, 0.05)[0], to_skin(p), mesh_distance(p, body_vertices, body_faces)[0]]
        ),
    )
    print(
        f"mannequin: {mannequin.name}; dense body {BODY}.obj, {len(body_vertices):,} vertices, "
        f"{len(body_faces):,} triangles, skinned rigidly to {len(set(bones.tolist()))} of the 24 SMPL bones"
    )
    print(
        f"walk: {frames} frames ({settle_frames(frames)} settling from rest), {len(walk)} frames a stride; "
        f"{garment.name} {len(garment.vertices)} vertices, cloth edge {EDGE * 100:g} cm"
    )

    def simulate(pieces, dense, skin=None):
        with blender_output():
            empty_scene()
            collection, obj, colliders = drape.setup(garment, pieces, settings, "bench")
            if dense:
                rig = bare_armature("bench body", mannequin.joints, collection)
                bind_weights(colliders[0], rig, {JOINT_NAMES[j]: (bones == j).astype(float) for j in set(bones)})
                bind_weights(obj, rig, _pins(obj, mannequin))
                bake_action(
                    rig,
                    JOINT_NAMES,
                    np.stack([p.rotations for p in motion]),
                    np.stack([p.translation for p in motion]),
                    "bench motion",
                )
            else:
                animate_drape(collection, colliders, obj, mannequin, walk, True, frames, skin)
            wall, _ = drape.bake(bpy.context.scene, obj, frames)
            cloth = drape.evaluated_vertices(obj)
            body = drape.evaluated_vertices(colliders[0]) if dense else None
        return float(np.mean(wall)), cloth, body

    start = time.perf_counter()
    pieces = collision_pieces(mannequin, True, settings.sphere_subdivisions, settings.cushion_subdivisions)
    convex_seconds, convex_cloth, _ = simulate(pieces, dense=False)
    skin_seconds, skin_cloth, _ = simulate([skin_piece], dense=False, skin=skin)
    dense_piece = [drape.mesh_piece(f"{BODY}.obj", body_vertices, body_faces)]
    dense_seconds, dense_cloth, posed_body = simulate(dense_piece, dense=True)
    print(f"(the three drapes and their set-up: {time.perf_counter() - start:.0f} s)")
    print(
        f"{'collider':<18}{'triangles':>10}{'s/frame':>9} | vs the dense body at the last frame, mm: "
        f"{'median':>6}{'p95':>6}{'inside':>7}{'deepest':>8}"
    )
    for label, triangles, seconds, cloth in (
        ("convex pieces", triangle_count(pieces), convex_seconds, convex_cloth),
        (f"skin ({settings.skin_level})", len(skin.faces), skin_seconds, skin_cloth),
        ("dense body", len(body_faces), dense_seconds, dense_cloth),
    ):
        fit = fit_statistics(mesh_distance(cloth, posed_body, body_faces)[0])
        print(
            f"{label:<18}{triangles:>10,}{seconds:>9.3f} | {'':40}{fit['median'] * 1e3:>6.1f}"
            f"{fit['p95'] * 1e3:>6.1f}{fit['penetrating']:>7}{fit['max_depth'] * 1e3:>8.1f}"
        )
    for label, seconds, cloth in (("convex pieces", convex_seconds, convex_cloth), ("skin", skin_seconds, skin_cloth)):
        apart = np.linalg.norm(cloth - dense_cloth, axis=1)
        print(
            f"{label}: {dense_seconds / seconds:.2f}x the dense body's speed; its dress and the dense body's per "
            f"vertex: median {np.median(apart) * 1e3:.1f} mm, 95th percentile {np.percentile(apart, 95) * 1e3:.1f} mm "
            "apart"
        )


def _pins(garment_object, mannequin):
    from ellimann_addon.blender.services.drape_motion import nearest_joint_weights

    return nearest_joint_weights(garment_object, mannequin.joints)


if __name__ == "__main__":
    run()
