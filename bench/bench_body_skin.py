"""The body skin (core.body) against today's smooth skin over the pieces (core.skin), on bodies the set has not
seen, in the same run: voxel IoU at 8 mm with the body (both meshes stood on the body's floor with their volume
centroids above the body's) and the per-vertex error (the body skin shares the body's topology), the tape's
reading of the five, and the time per request.

- Leave-one-out over the six bodies of ../shared/refmodels (female) and ../shared/refmodels_male: the held-out
  body's twin from the other five bodies (the body skin) and from the other five's RMs (today's exact skin over
  the pieces; the six RMs built once by tools.figures.held_out.six_rms, a few minutes per set); beside them the bodies'
  blend alone and the least-squares best blend of the five (fitted to the answer: what five bodies can give).
- The 80 bodies of ../shared/bodies (never seen by the shipped sets): their twins from the shipped set.
- Speed: an exact body skin per request against today's skin at the preview and final levels and exact mode.

    python -m bench.bench_body_skin                       # both sets, every 8th bank body, with today's skin
    python -m bench.bench_body_skin --bank-step 1 --sets female --no-pieces
    python -m bench.bench_body_skin --grid                # the 243 grid: met, refused by kind (a minute a set)
    python -m bench.bench_body_skin --gaps                # the cloth gap: each RM's pieces against its body skin
    python -m bench.bench_body_skin --speed 5             # the speed alone, five and eleven, against today's skin
    python -m bench.bench_body_skin --grid --model idw    # the grid by IDW over the five (default: the set's model)
"""

import argparse
import statistics
import time

import numpy as np

from ellimann_addon.core.body.model import IdwBodyModel
from ellimann_addon.core.body.skin import BODY_MODELS, BodySkinMaker, body_skin_maker
from ellimann_addon.core.geometry.volume import IOU_MARGIN, IOU_SPACING, BodyVolume, mesh_voxel_iou
from ellimann_addon.core.mannequin.skin_record import SkinSettings
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.skin.exact import exact_skin
from ellimann_addon.core.skin.surface import build_skin
from ellimann_addon.core.synthesis.bodies import load_set_bodies
from ellimann_addon.core.synthesis.shipped import named_reference_set, reference_folder
from ellimann_addon.core.synthesis.synthesize import synthesize_batch
from tools.shipped.add_bodies import set_bodies
from tools.shipped.reference_sets import BUILD_SETS, SHARED

SPACING = 0.008  # m: the voxels
TODAY = "today's skin"
MODEL = [None]  # --model: the body model of the grid, the speed and the gaps (None: the set's best, ridge where it
# has a body space); the held-out and bank rows are IDW over bodies the held-out one is not among


def centroid(vertices, faces):
    """The volume centroid of a closed mesh."""
    tri = vertices[faces]
    weight = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))
    return (weight[:, None] * tri.sum(axis=1)).sum(axis=0) / (4.0 * weight.sum())


def stood(vertices, faces, body_vertices, body_faces):
    """``vertices`` moved onto the body's floor, its volume centroid above the body's."""
    shift = np.zeros(3)
    shift[:2] = centroid(body_vertices, body_faces)[:2] - centroid(vertices, faces)[:2]
    shift[2] = body_vertices[:, 2].min() - vertices[:, 2].min()
    return vertices + shift


def iou(vertices, faces, body_vertices, body_faces, grid):
    return mesh_voxel_iou(stood(vertices, faces, body_vertices, body_faces), faces, grid)


def vertex_error(vertices, faces, body_vertices):
    """(mean, p95) mm of the distance between corresponding vertices, stood alike."""
    distance = np.linalg.norm(stood(vertices, faces, body_vertices, faces) - body_vertices, axis=1) * 1e3
    return float(distance.mean()), float(np.percentile(distance, 95))


def best_blend(bodies, body_vertices):
    """The least-squares blend of ``bodies`` (affine weights) nearest to the body, each on its floor."""
    stack = np.stack([bodies.vertices(i) - [0, 0, bodies.vertices(i)[:, 2].min()] for i in range(len(bodies))])
    target = body_vertices - [0, 0, body_vertices[:, 2].min()]
    base, rest = stack[0], stack[1:] - stack[0]
    weights = np.linalg.lstsq(rest.reshape(len(rest), -1).T, (target - base).ravel(), rcond=None)[0]
    return base + np.tensordot(weights, rest, axes=1)


def five(values):
    return {key: float(values[key]) for key in MEASUREMENTS}


def held_out_rows(name, with_pieces):
    """Leave-one-out over the six bodies of the set's refmodels folder."""
    build_set = BUILD_SETS[name]
    six = [build_set.reference_body, "small_slim", "tall_slim", "small_chubby", "tall_chubby", "average"]
    bodies = set_bodies(build_set, six)
    rms = None
    if with_pieces:
        from tools.figures.held_out import six_rms, subset_set

        rms, targets, _, _ = six_rms(build_set.refmodels, 2, build_set)
    rows = []
    for held in range(len(six)):
        others = bodies.subset([i for i in range(len(six)) if i != held])
        maker = BodySkinMaker(others, IdwBodyModel(others))
        body, faces = bodies.vertices(held), bodies.faces
        request = five(bodies.measurements(held))
        row = {"body": six[held]}
        row.update(_twins(maker, body, faces, request))
        row["best blend"] = iou(best_blend(others, body), faces, body, faces, _grid(body, faces))
        if rms is not None:
            reference = subset_set(rms, targets, [n for n in rms if n != six[held]])
            row.update(_pieces(reference, body, faces, request, row["skin"], body))
        rows.append(row)
    return rows


def _grid(body, faces):
    return BodyVolume(body, faces).grid(SPACING, margin=IOU_MARGIN)


def _twins(maker, body, faces, request):
    grid = _grid(body, faces)
    started = time.perf_counter()
    skin = maker.make(request)
    seconds = time.perf_counter() - started
    blend = maker.interpolated(request)[0]
    found = skin.measure().values
    return {
        "body skin": iou(skin.vertices, faces, body, faces, grid),
        "blend alone": iou(blend, faces, body, faces, grid),
        "error": vertex_error(skin.vertices, faces, body),
        "blend error": vertex_error(blend, faces, body),
        "miss": max(abs(found[key] - request[key]) for key in MEASUREMENTS),
        "seconds": seconds,
        "skin": skin,
    }


def cloth_gap(mannequin, vertices, faces):
    """tools.figures.cloth_gap.surface_gap of a body skin against ``mannequin`` (its pieces), the mannequin stood in the
    skin as tools/figures/cloth_gap.py stands it in a body (floors alike, the volumes' centroids on one vertical line):
    how far the skin lies outside the pieces a garment rests on."""
    from tools.figures.cloth_gap import surface_gap
    from tools.figures.overlap import standing_in

    grid = BodyVolume(vertices, faces).grid(IOU_SPACING, margin=IOU_MARGIN)
    lowest = float(
        np.min(mannequin.center[:, 2] - np.linalg.norm(mannequin.rotation[:, 2, :] * mannequin.semi_axes, axis=1))
    )
    placed = mannequin.copy(center=mannequin.center + [0.0, 0.0, vertices[:, 2].min() - lowest])
    return surface_gap(standing_in(grid, placed), vertices, faces)


def rm_gaps(name):
    """{stem: cloth_gap} of each RM of the shipped set against the body skin at its targets."""
    reference = named_reference_set(name)
    maker = body_skin_maker(reference, MODEL[0])
    out = {}
    for i, stem in enumerate(reference.names):
        skin = maker.make(reference.manifest.targets_cm[stem])
        out[stem] = cloth_gap(reference.mannequins[i], skin.vertices, skin.faces)
    return out


def _pieces(reference, body, faces, request, skin=None, held_body=None):
    grid = _grid(body, faces)
    mannequin = synthesize_batch(reference, [[request[key] for key in MEASUREMENTS]]).mannequin(0)
    out = {}
    if skin is not None:
        out["gap"] = cloth_gap(mannequin, skin.vertices, skin.faces)
    if held_body is not None:
        out["body gap"] = cloth_gap(mannequin, held_body, faces)
    for level in ("preview", "final"):
        started = time.perf_counter()
        skin = build_skin(mannequin, SkinSettings.at_level(level))
        out[f"{level} s"] = time.perf_counter() - started
    started = time.perf_counter()
    skin = exact_skin(mannequin, SkinSettings.at_level("final"), request).skin
    out["exact s"] = time.perf_counter() - started
    out["today's skin"] = iou(skin.vertices, skin.faces, body, faces, grid)
    return out


def bank_rows(name, step, with_pieces):
    """The bank's bodies (../shared/bodies/<sex>.npz), every ``step``-th, against the shipped set."""
    reference = named_reference_set(name)
    bodies = load_set_bodies(reference_folder(name))
    maker = BodySkinMaker(bodies, ranges=reference.ranges)  # IDW over the five: the bank is in the ridge's space
    bank = np.load(SHARED / "bodies" / f"{name}.npz")
    rows = []
    for i in range(0, len(bank["vertices"]), step):
        body = bank["vertices"][i].astype(float)
        request = maker.tape.measure(body, MEASUREMENTS)  # the same tape, the labels' arms
        row = {"body": f"bank {i}"}
        try:
            row.update(_twins(maker, body, bodies.faces, request))
        except ValueError as error:
            row["refused"] = str(error)
            rows.append(row)
            continue
        if with_pieces:
            row.update(_pieces(reference, body, bodies.faces, request))
        rows.append(row)
    return rows


def summary(label, rows):
    made = [row for row in rows if "body skin" in row]
    line = f"{label}: {len(made)} of {len(rows)} made"
    for key in ("body skin", "blend alone", "best blend", "today's skin"):
        values = [row[key] for row in made if key in row]
        if values:
            line += f"; IoU {key} {statistics.mean(values):.3f} (min {min(values):.3f})"
    errors = [row["error"] for row in made]
    mean, p95 = np.mean([e[0] for e in errors]), np.mean([e[1] for e in errors])
    line += f"; vertex error {mean:.1f} mm mean, p95 {p95:.1f} mm"
    line += f"; worst miss of the five {max(row['miss'] for row in made) * 10:.2f} mm"
    body_s = statistics.median(row["seconds"] for row in made)
    line += f"; body skin {body_s * 1e3:.0f} ms a request"
    for level in ("preview s", "final s", "exact s"):
        values = [row[level] for row in made if level in row]
        if values:
            median = statistics.median(values)
            line += f"; today's {level[:-2]} {median:.2f} s ({median / body_s:.0f}x)"
    print(line)
    gaps = [(row["gap"], row.get("body gap")) for row in made if "gap" in row]
    if gaps:
        print(f"  cloth gap, body skin outside the synthesized pieces: {gap_words([g for g, _ in gaps])}")
        if all(b is not None for _, b in gaps):
            print(f"  cloth gap, the held-out body itself outside them: {gap_words([b for _, b in gaps])}")
    for row in rows:
        if "refused" in row:
            print(f"  {row['body']}: {row['refused']}")


def gap_words(gaps):
    """Mean over the rows of each surface_gap figure, in words (mm, %)."""
    mean = {key: float(np.mean([gap[key] for gap in gaps])) for key in gaps[0]}
    return (
        f"{mean['outside']:.0%} of the surface outside; area-weighted median {mean['median'] * 1e3:.1f} mm, "
        f"p95 {mean['p95'] * 1e3:.1f} mm (over the part outside: median {mean['outside_median'] * 1e3:.1f} mm, "
        f"p95 {mean['outside_p95'] * 1e3:.1f} mm)"
    )


def grid_counts(name):
    """Over the 243 grid of the shipped set's ranges (3 levels each): {outcome: count} and the worst miss (cm) of
    the five by the whole measurer, the refusals' lines by kind, the median seconds a skin."""
    import itertools

    from ellimann_addon.core.body.correct import BodySkinError

    reference = named_reference_set(name)
    maker = body_skin_maker(reference, MODEL[0])
    levels = {key: (low, 0.5 * (low + high), high) for key, (low, high) in reference.ranges.items()}
    counts, worst, seconds, lines = {}, 0.0, [], []
    for combo in itertools.product(range(3), repeat=len(MEASUREMENTS)):
        request = {key: levels[key][i] for key, i in zip(MEASUREMENTS, combo)}
        started = time.perf_counter()
        try:
            skin = maker.make(request)
        except BodySkinError as error:
            text = str(error)
            kind = (
                "beyond any body's proportions"
                if "no body has" in text
                else "arms through the trunk"
                if "arms would" in text
                else "folding"
                if "fold" in text
                else "stretched or squeezed"
                if "triangles" in text
                else "beyond the correction's bounds"
            )
            counts[kind] = counts.get(kind, 0) + 1
            lines.append(f"{''.join(map(str, combo))} {text}")
            continue
        seconds.append(time.perf_counter() - started)
        found = skin.measure().values
        worst = max(worst, max(abs(found[key] - request[key]) for key in MEASUREMENTS))
        counts["met"] = counts.get("met", 0) + 1
        if skin.abduction > 0.0:
            counts["met, arms raised"] = counts.get("met, arms raised", 0) + 1
    return counts, worst, lines, statistics.median(seconds)


def timed(times, function, *args):
    started = time.perf_counter()
    function(*args)
    times.append(time.perf_counter() - started)


def speed(name, count=5, seed=7):
    """Median seconds of an exact body skin (the five; the eleven) against today's skin over the pieces (preview,
    final, exact with the five; exact with the eleven) in the same run, at ``count`` requests: the set's bodies'
    own measurements each moved by up to 3 % (the first ``count`` of them, in turn)."""
    from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS

    reference = named_reference_set(name)
    bodies = load_set_bodies(reference_folder(name))
    maker = body_skin_maker(reference, MODEL[0])
    rng = np.random.default_rng(seed)
    times = {key: [] for key in ("body five", "body eleven", "preview", "final", "exact five", "exact eleven")}
    for i in range(count):
        own = bodies.measurements(i % len(bodies))
        request = {key: value * (1.0 + rng.uniform(-0.03, 0.03)) for key, value in own.items()}
        five = {key: request[key] for key in MEASUREMENTS}
        extra = {key: request[key] for key in EXTRA_MEASUREMENTS}
        timed(times["body five"], maker.make, five)
        timed(times["body eleven"], maker.make, five, extra)
        mannequin = synthesize_batch(reference, [[five[key] for key in MEASUREMENTS]]).mannequin(0)
        final = SkinSettings.at_level("final")
        timed(times["preview"], build_skin, mannequin, SkinSettings.at_level("preview"))
        timed(times["final"], build_skin, mannequin, final)
        timed(times["exact five"], exact_skin, mannequin, final, five)
        timed(times["exact eleven"], exact_skin, mannequin, final, five, extra)
    return {key: statistics.median(values) for key, values in times.items()}


def run(sets=("female", "male"), bank_step=8, with_pieces=True, held_out=True, quick=False):
    """``quick``: two bank bodies of the female set, without today's skin (that it runs, not its figures)."""
    if quick:
        sets, bank_step, with_pieces, held_out = ("female",), 40, False, False
    for name in sets:
        if held_out:
            rows = held_out_rows(name, with_pieces)
            for row in rows:
                print(
                    f"{name} held out {row['body']:<17} body skin {row['body skin']:.3f} blend {row['blend alone']:.3f}"
                    f" best blend {row['best blend']:.3f}"
                    + (f" today's skin {row[TODAY]:.3f}" if TODAY in row else "")
                    + f" error {row['error'][0]:.1f}/{row['error'][1]:.1f} mm"
                )
            summary(f"{name}, six held out", rows)
        if bank_step:
            summary(f"{name}, bank every {bank_step}", bank_rows(name, bank_step, with_pieces))


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m bench.bench_body_skin", description=__doc__.split("\n")[0])
    parser.add_argument("--sets", default="female,male")
    parser.add_argument("--bank-step", type=int, default=8, help="every n-th bank body (0: none)")
    parser.add_argument("--no-pieces", action="store_true", help="without today's skin (fast)")
    parser.add_argument("--no-held-out", action="store_true")
    parser.add_argument("--grid", action="store_true", help="only the 243 grid's counts (met, refused by kind)")
    parser.add_argument("--gaps", action="store_true", help="only the RMs' cloth gap against their body skins")
    parser.add_argument("--speed", type=int, metavar="N", help="only the speed, at N requests a set")
    models = [m for m in BODY_MODELS if m]
    parser.add_argument("--model", choices=models, help="the grid's, speed's and gaps' body model (default the set's)")
    args = parser.parse_args(argv)
    MODEL[0] = args.model
    if args.speed:
        for name in args.sets.split(","):
            found = speed(name, args.speed)
            five, eleven = found["body five"], found["body eleven"]
            print(
                f"{name}: body skin {five * 1e3:.0f} ms (the five), {eleven * 1e3:.0f} ms (the eleven); today's skin "
                f"preview {found['preview']:.2f} s ({found['preview'] / five:.0f}x), final {found['final']:.2f} s "
                f"({found['final'] / five:.0f}x), exact {found['exact five']:.2f} s "
                f"({found['exact five'] / five:.0f}x); exact with the eleven {found['exact eleven']:.2f} s "
                f"({found['exact eleven'] / eleven:.0f}x)"
            )
        return
    if args.grid:
        for name in args.sets.split(","):
            counts, worst, lines, median = grid_counts(name)
            print(
                f"{name} 243 grid: {counts}; worst miss of the five {worst * 10:.2f} mm; {median * 1e3:.0f} ms a skin"
            )
            for line in lines:
                print(f"  {line}")
        return
    if args.gaps:
        for name in args.sets.split(","):
            gaps = rm_gaps(name)
            for stem, gap in gaps.items():
                print(f"{name} {stem}: {gap_words([gap])}")
            print(f"{name} RMs: {gap_words(list(gaps.values()))}")
        return
    run(args.sets.split(","), args.bank_step, not args.no_pieces, not args.no_held_out)


if __name__ == "__main__":
    main()
