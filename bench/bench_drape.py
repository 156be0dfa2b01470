"""Draping on the convex mannequin vs on the dense body mesh it stands for (Blender cloth, one run).

The Average Reference Mannequin (``reference_blends/average.json``, traced over and measured like
``../shared/refmodels/average.obj``: He 159.00, Sh 43.03, Br 116.97, Wa 103.99, Hi 117.00 cm) and
that dense body are the two collision bodies. One garment per kind is built from the mannequin's
m_T and moved clear of both bodies, then draped with the same cloth settings on:
  (a) the mannequin's convex pieces as collision meshes (cushions + the ellipsoids not in one, or
      ellipsoids only), at several icosphere levels;
  (b) the mannequin's skin (core.skin) as one collision mesh, at the preview (10 mm) and final (5 mm) levels;
  (c) the dense body (26,692 triangles): the baseline.
Per run: seconds per simulated frame (the mean step of frame_set, best of REPEAT runs, by the wall
clock, with this process's CPU time beside it: Blender runs parts of the cloth step on two threads,
so CPU time can exceed wall time; the cloth alone, with no collider, gives the floor), collider
triangles, and the final garment against the DENSE body surface (signed distances, vertices
inside) for all, so the comparison is fair; (a) also against its own exact pieces, (b) against its own
mesh. "Equal fit" for the resolution sweep (both garments, cushion, ellipsoid and skin colliders each
against the finest of their own kind): median and 95th-percentile gap to the dense body within FIT_TOLERANCE (p95: twice
that) of the finest colliders', vertices inside it within PENETRATING_TOLERANCE of the garment of
theirs, and no vertex more than FIT_TOLERANCE inside its own exact collider (a coarse collider lets the
cloth into it).
"""

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
from ellimann_addon.core.synthesis.synthesize import REFERENCE_FOLDER

ROOT = pathlib.Path(__file__).resolve().parents[1]
REFMODELS = ROOT.parent / "shared" / "refmodels"
BODY = "average"
FRAMES = 40
EDGE = 0.025  # m, the garments' cloth resolution
REPEAT = 3
FIT_TOLERANCE = 0.001  # m
# Vertices inside the dense body come mostly from the pieces lying inside the skin, at any collider
# resolution; a few more than the finest collider's (this share of the garment) is still equal fit.
PENETRATING_TOLERANCE = 0.01
# Collider resolutions tried for (a): (label, cushions, sphere level, cushion level).
SWEEP = (
    ("cushions L1/L1", True, 1, 1),
    ("cushions L2/L1", True, 2, 1),
    ("cushions L1/L2", True, 1, 2),
    ("cushions L2/L2", True, 2, 2),
    ("cushions L3/L3", True, 3, 3),
    ("ellipsoids L1", False, 1, 0),
    ("ellipsoids L2", False, 2, 0),
    ("ellipsoids L3", False, 3, 0),
)
HEADLINE = "cushions L2/L2"


SKINS = ("preview", "final")  # the skin as the collider, at these levels (core.drape.colliders.skin_collider)
SKIN_SAMPLE = 4  # the skin's vertices measured against the dense body: every 4th (25,800 at preview take ~20 s)


def run(frames=FRAMES, repeat=REPEAT, sweep=SWEEP, kinds=("tube_dress", "t_shirt"), skins=SKINS, quick=False):
    """``quick``: the tube dress, 2 frames, once, on one cushion collider and the dense body, no skin (checks that it
    runs)."""
    if quick:
        frames, repeat, sweep, kinds, skins = 2, 1, SWEEP[:1], ("tube_dress",), ()
    source = REFERENCE_FOLDER / f"{BODY}.json"
    body_path = REFMODELS / f"{BODY}.obj"
    if not source.is_file() or not body_path.is_file():
        print(f"skipped: needs {source} (the shipped Reference Mannequins) and {body_path}")
        return
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="ellimann-bench-"))
    import ellimann_addon

    ellimann_addon.register()
    try:
        body = read_obj(body_path, up="z")
        compare(
            Mannequin.load(source),
            body.vertices,
            body.faces,
            frames=frames,
            repeat=repeat,
            sweep=sweep,
            kinds=kinds,
            skins=skins,
        )
    finally:
        ellimann_addon.unregister()


def compare(
    mannequin,
    body_vertices,
    body_faces,
    frames=FRAMES,
    repeat=REPEAT,
    sweep=SWEEP,
    kinds=("tube_dress", "t_shirt"),
    skins=SKINS,
):
    """Drape each garment of ``kinds`` on every collider of ``sweep``, on the skin at each level of ``skins`` and on
    the dense body; print the table."""
    import bpy

    from ellimann_addon.blender.services import drape
    from ellimann_addon.blender.services.chatter import blender_output
    from ellimann_addon.blender.services.scene import empty_scene

    exact = BodyPieces(mannequin, cushions=True, subdivisions=4)
    own = {True: exact, False: BodyPieces(mannequin)}  # the exact pieces of each kind of collider

    def dense(points):
        return mesh_distance(points, body_vertices, body_faces)[0]

    print(
        f"mannequin: {mannequin.name} ({len(mannequin)} ellipsoids, {len(mannequin.topology.cushion_pairs)} "
        f"cushion pairs), m_T " + ", ".join(f"{k} {v:.2f}" for k, v in mannequin.measure().items()) + " cm"
    )
    print(f"dense body: {BODY}.obj, {len(body_vertices):,} vertices, {len(body_faces):,} triangles")
    gap = dense(exact_samples(mannequin))
    print(
        f"mannequin surface vs dense body: median {np.median(gap) * 1e3:.1f} mm, {np.mean(gap < 0) * 100:.0f}% of "
        "it inside the body (the pieces are fitted mostly inside the skin)"
    )
    built = {}
    for level in skins:
        start = time.perf_counter()
        built[level] = skin_collider(mannequin, level)
        skin, seconds = built[level][0], time.perf_counter() - start
        gap = dense(skin.vertices[::SKIN_SAMPLE])
        print(
            f"skin ({level}, {len(skin.faces):,} triangles, made in {seconds:.1f} s) vs dense body (every "
            f"{SKIN_SAMPLE}th vertex): median {np.median(gap) * 1e3:.1f} mm, {np.mean(gap < 0) * 100:.0f}% of it "
            "inside the body"
        )
    print(f"cloth: settings {drape.DrapeSettings(frames=frames, edge=EDGE)}")
    colliders = [("dense body", [drape.mesh_piece(f"{BODY}.obj", body_vertices, body_faces)], None)]
    for label, cushions, sphere, cushion in sweep:
        pieces = collision_pieces(mannequin, cushions, sphere, cushion)
        colliders.append((label, pieces, lambda p, c=cushions: own[c].signed_distance(p, drape.FIT_CUTOFF)[0]))
    for level, (skin, piece) in built.items():
        colliders.append((f"skin {level}", [piece], lambda p, s=skin: mesh_distance(p, s.vertices, s.faces)[0]))
    skin_field = skin_distance(next(iter(built.values()))[0]) if built else None  # one field at any voxel

    def simulate(garment, pieces):
        settings = drape.DrapeSettings(frames=frames, edge=EDGE)
        with blender_output():
            empty_scene()
            _, obj, _ = drape.setup(garment, pieces, settings, "bench")
            wall, cpu = drape.bake(bpy.context.scene, obj, frames)
        return float(np.mean(wall)), float(np.mean(cpu)), drape.evaluated_vertices(obj)

    def every_body(points):
        nearest = np.minimum(exact.signed_distance(points, 0.05)[0], dense(points))
        return nearest if skin_field is None else np.minimum(nearest, skin_field(points))

    for kind in kinds:
        garment = garments.make_garment(mannequin, kind, edge=EDGE)
        start = time.perf_counter()
        garment = garments.clear_of(garment, every_body)
        print(
            f"\n== {garment.name}: {len(garment.vertices)} vertices, {len(garment.faces)} triangles, "
            f"{len(garment.seams)} seams, {len(garment.pins)} pins; {garment.pattern['cleared']} vertices moved "
            f"clear of every body ({time.perf_counter() - start:.1f} s)"
        )
        rows = {}
        # The cloth alone (no collider: it falls freely) is the floor under every collider's cost.
        free = min(simulate(garment, [])[0] for _ in range(repeat))
        for label, pieces, own_distance in colliders:
            results = [simulate(garment, pieces) for _ in range(repeat)]
            vertices = results[0][2]
            row = {
                "seconds": min(r[0] for r in results),
                "cpu": min(r[1] for r in results),
                "triangles": triangle_count(pieces),
                "vertices": vertices,
                "dense": fit_statistics(dense(vertices)),
                "own": None if own_distance is None else fit_statistics(own_distance(vertices)),
            }
            if len(garment.seams):
                gaps = np.linalg.norm(vertices[garment.seams[:, 0]] - vertices[garment.seams[:, 1]], axis=1)
                row["seams"] = (float(np.median(gaps)), float(gaps.max()))
            rows[label] = row
        report(rows, garment, free)


def exact_samples(mannequin, count=100):
    """Points on the mannequin's outer surface (ellipsoid samples not inside another piece)."""
    from ellimann_addon.core.geometry.ellipsoid import sample_surface

    points = sample_surface(mannequin.rotation, mannequin.center, mannequin.semi_axes, count).reshape(-1, 3)
    return points[BodyPieces(mannequin).signed_distance(points)[0] > -1e-9]


def report(rows, garment, free):
    base = rows["dense body"]
    headline = HEADLINE if HEADLINE in rows else next(label for label in rows if label != "dense body")
    print(
        f"cloth alone (no collider) {free:.3f} s/frame; above that, collisions cost "
        f"{base['seconds'] - free:.3f} with the dense body and {rows[headline]['seconds'] - free:.3f} with "
        f"{headline} ({(base['seconds'] - free) / max(rows[headline]['seconds'] - free, 1e-9):.1f}x)"
    )
    print(
        "s/frame: wall (CPU); distances in mm; 'inside': garment vertices inside that surface; "
        "speed-up = dense s/frame / this"
    )
    print(
        f"{'collider':<16}{'triangles':>10}{'s/frame':>15}{'speed-up':>9} | vs dense body: {'median':>6}{'p05':>6}"
        f"{'p95':>6}{'inside':>7}{'deepest':>8} | vs own collider: {'inside':>6}{'deepest':>8}"
        + (" | seams median/max" if len(garment.seams) else "")
    )
    for label, row in rows.items():
        d, own = row["dense"], row["own"]
        cells = (
            f"{label:<16}{row['triangles']:>10,}{row['seconds']:>8.3f} ({row['cpu']:.3f})"
            f"{base['seconds'] / row['seconds']:>8.2f}x"
            f" | {'':14}{d['median'] * 1e3:>6.1f}{d['p05'] * 1e3:>6.1f}{d['p95'] * 1e3:>6.1f}"
            f"{d['penetrating']:>7}{d['max_depth'] * 1e3:>8.1f}"
        )
        cells += f" | {'':14}{own['penetrating']:>6}{own['max_depth'] * 1e3:>8.1f}" if own else f" | {'(the same)':>28}"
        if "seams" in row:
            cells += f" | {row['seams'][0] * 1e3:6.1f} / {row['seams'][1] * 1e3:5.1f}"
        print(cells)
    shift = np.linalg.norm(rows[headline]["vertices"] - base["vertices"], axis=1)
    print(
        f"same garment, {headline} vs dense body, per vertex: median {np.median(shift) * 1e3:.1f} mm, "
        f"95th percentile {np.percentile(shift, 95) * 1e3:.1f} mm apart"
    )
    for kind in ("cushions", "ellipsoids", "skin"):
        print(best_at_equal_fit({label: row for label, row in rows.items() if label.startswith(kind)}, kind))


def best_at_equal_fit(sweep, kind):
    """The fastest collider of one kind whose drape fits as the finest collider of that kind does."""
    if len(sweep) < 2:
        return f"{kind}: fewer than two resolutions, no comparison"
    finest_label = max(sweep, key=lambda label: sweep[label]["triangles"])
    finest = sweep[finest_label]["dense"]
    equal = [
        label
        for label, row in sweep.items()
        if abs(row["dense"]["median"] - finest["median"]) <= FIT_TOLERANCE
        and abs(row["dense"]["p95"] - finest["p95"]) <= 2 * FIT_TOLERANCE
        and row["dense"]["penetrating"] <= finest["penetrating"] + PENETRATING_TOLERANCE * len(row["vertices"])
        and row["own"]["max_depth"] <= FIT_TOLERANCE
    ]
    criteria = (
        f"median within {FIT_TOLERANCE * 1e3:g} mm, p95 within {2 * FIT_TOLERANCE * 1e3:g} mm and vertices "
        f"inside the dense body within {PENETRATING_TOLERANCE:.0%} of the garment of {finest_label}'s, none "
        f"over {FIT_TOLERANCE * 1e3:g} mm inside its own exact collider"
    )
    if not equal:
        return f"{kind}: no resolution fits as {finest_label} does ({criteria})"
    best = min(equal, key=lambda label: sweep[label]["seconds"])
    return (
        f"{kind}, best speed at equal fit ({criteria}): {best}, {sweep[best]['seconds']:.3f} s/frame, "
        f"{sweep[best]['triangles']:,} triangles (equal fit: {', '.join(equal)})"
    )


if __name__ == "__main__":
    run()
