"""Procedural garments sized from a mannequin's measurements, placed around its body ready to drape.

A garment is a triangle mesh in metres (faces counter-clockwise seen from outside, i.e. normals
away from the body) plus ``seams``: vertex pairs that Blender cloth's sewing springs pull
together (they become loose edges). Where pattern panels meet along a seam that is already closed
in the initial shape, the vertices are simply shared (welded).

Initial shapes are built on *rings*: the horizontal section of the body at a height (closed-form
ellipses, :func:`ellipsoid.section_at_height`), their convex hull, offset outward. The offset of a
convex curve by t has perimeter P + 2 pi t, so a ring of any perimeter W >= P is the hull offset by
(W - P) / (2 pi): a garment panel of width W wraps the body at that height unstretched, with
clearance (W - P) / (2 pi) all round. Nothing starts inside the body (tests check it).

- :func:`tube_dress`: one rectangle sewn at the centre back into a tube (welded), width
  max(Br, Hi) * (1 + ease), from above the bust to mid-thigh.
- :func:`t_shirt`: front and back panels with short sleeves. Below the armpit front and back are
  one tube whose ring perimeter follows the pattern girths Hi -> Wa -> Br (linear between their
  heights) * (1 + ease); above it the front and back panels rise over the chest and shoulder
  blades to just below the shoulder line, where shoulder-seam pairs join them over the shoulders.
  Each sleeve is a tube round the upper arm, its top ring sewn to the armhole (pairs).
Sizes come from the mannequin's m_T (default), its target measurements (``measurements="target"``)
or a dict in cm. Heights are fractions of the body's height above its lowest point.

Both wrap the ellipsoids. A body with other surfaces (cushion hulls, which fill the hollows
between their two ellipsoids, or a dense body mesh) may reach through that initial shape:
:func:`clear_of` pushes such vertices out before a simulation starts.
"""

import numpy as np

from ..constants import CM_PER_M
from ..errors import ElliMannError
from ..geometry.ellipsoid import axis_extent
from ..settings import DEFAULT_EDGE, EDGE_RANGE, GARMENT_WORDS
from .patterns import (  # noqa: F401  (clear_of: public here, garments.clear_of)
    MIN_CLEARANCE,
    RING_SAMPLES,
    Garment,
    body_extent,
    check_range,
    clear_of,
    clear_rows,
    girth_perimeters,
    grid_faces,
    hull_rings,
    pattern_measurements,
    resample_polyline,
)
from .t_shirt import pattern_girth, silhouette_top, t_shirt

# ----------------------------------------------------------------------------------------------
# Tube dress


def tube_dress(mannequin, ease=0.06, edge=DEFAULT_EDGE, measurements=None, top=0.75, hem=0.38):
    """A strapless tube dress from ``top`` (fraction of He, above the bust) to ``hem`` (mid-thigh).

    Pattern: one rectangle of width max(Br, Hi) * (1 + ease) and the length between the two
    heights, sewn at the centre back (welded: the result is an open tube, two boundary loops).
    If the body's girth somewhere in between needs more (plus MIN_CLEARANCE all round), the width
    grows to that and ``pattern["enlarged"]`` says so. Rings are the girth sections (arms left out).
    """
    mannequin.check()
    ease = check_range("ease", ease, 0.0, 1.0)
    edge = check_range("edge", edge, *EDGE_RANGE)
    top = check_range("top", top, 0.0, 1.0)
    hem = check_range("hem", hem, 0.0, 1.0)
    if hem >= top:
        raise ElliMannError(f"hem: must be below top ({top}), got {hem}")
    sizes = pattern_measurements(mannequin, measurements)
    bottom, height = body_extent(mannequin)
    z_hem, z_top = bottom + hem * height, bottom + top * height
    rows = max(2, int(np.ceil((z_top - z_hem) / edge)) + 1)
    z = np.linspace(z_hem, z_top, rows)
    girth = mannequin.topology.girth_mask
    perimeter, (centre, k, active) = girth_perimeters(mannequin, girth, z)
    requested = max(sizes["Br"], sizes["Hi"]) / CM_PER_M * (1.0 + ease)
    needed = float(perimeter.max()) + 2.0 * np.pi * MIN_CLEARANCE
    width = max(requested, needed)
    columns = max(12, int(np.ceil(width / edge)))
    polygons = hull_rings(centre, k, active, (width - perimeter) / (2.0 * np.pi))
    start = RING_SAMPLES // 4  # direction +Y: the centre back, where the pattern's seam is
    rings = np.stack([resample_polyline(np.roll(p, -start, axis=0), columns, closed=True) for p in polygons])
    vertices = np.concatenate([rings, np.broadcast_to(z[:, None, None], (rows, columns, 1))], axis=-1)
    # Arms are not in the girth sections: where a ring would touch one, the dress ends below it.
    rows = clear_rows(mannequin, vertices)
    if rows < 2:
        raise ElliMannError("mannequin: the arms leave no room for a dress above the hem")
    vertices, z_top = vertices[:rows], z[rows - 1]
    return Garment(
        name="Tube dress",
        vertices=vertices.reshape(-1, 3),
        faces=grid_faces(rows, columns, closed=True),
        panel=np.zeros(rows * columns, dtype=int),
        panel_names=("tube",),
        pins=(rows - 1) * columns + np.arange(columns),
        pattern={
            "width_cm": width * CM_PER_M,
            "requested_width_cm": requested * CM_PER_M,
            "length_cm": (z_top - z_hem) * CM_PER_M,
            "ease": ease,
            "enlarged": width > requested,
            "measurements_cm": sizes,
            "top": (z_top - bottom) / height,
            "hem": hem,
            "edge": edge,
        },
    )


# The garments, by the key the CLI and the Drape panel use: builder, the panel's label and description, the
# command line's words (core.drape.settings.DRAPE["garment"] makes both from here).
GARMENTS = {  # kind: (builder, label, description, the command line's words: core.settings.GARMENT_WORDS)
    kind: (builder, *GARMENT_WORDS[kind]) for kind, builder in (("tube_dress", tube_dress), ("t_shirt", t_shirt))
}
BUILDERS = {kind: builder for kind, (builder, *_) in GARMENTS.items()}


def make_garment(mannequin, kind, **options):
    """The garment ``kind`` (a BUILDERS key) for ``mannequin``; ``options`` go to its builder."""
    if kind not in BUILDERS:
        raise ElliMannError(f"garment: must be one of {', '.join(BUILDERS)}, got {kind!r}")
    return BUILDERS[kind](mannequin, **options)


def estimate_vertices(mannequin, kind, edge=DEFAULT_EDGE):
    """About how many vertices ``make_garment(mannequin, kind, edge=edge)`` would make, without making it.

    From the garment's size (the builders' own pattern widths and heights, at their default options:
    m_T and a few body sections) and the edge length: a grid of (length / edge) x (width / edge)
    nodes, plus the sleeves of a T-shirt. Cheap at any edge, where building a fine garment takes
    minutes and gigabytes; within some 15% of the real count for the shipped bodies (tests check it).
    """
    if kind not in BUILDERS:
        raise ElliMannError(f"garment: must be one of {', '.join(BUILDERS)}, got {kind!r}")
    edge = check_range("edge", edge, *EDGE_RANGE)
    mannequin.check()
    options = _defaults(BUILDERS[kind])
    sizes = pattern_measurements(mannequin)
    bottom, height = body_extent(mannequin)
    girth = mannequin.topology.girth_mask
    if kind == "tube_dress":
        z_hem, z_top = bottom + options["hem"] * height, bottom + options["top"] * height
        perimeter, _ = girth_perimeters(mannequin, girth, np.linspace(z_hem, z_top, 16))
        requested = max(sizes["Br"], sizes["Hi"]) / CM_PER_M * (1.0 + options["ease"])
        width = max(requested, float(perimeter.max()) + 2.0 * np.pi * MIN_CLEARANCE)
        rows = max(2, int(np.ceil((z_top - z_hem) / edge)) + 1)
        return rows * max(12, int(np.ceil(width / edge)))
    # T-shirt: body tube and yokes from the hem to below the shoulders, then two sleeves.
    z_hem, z_sh = bottom + options["hem"] * height, bottom + mannequin.section_fractions["Sh"] * height
    z = np.linspace(z_hem, z_sh, 16)
    perimeter, _ = girth_perimeters(mannequin, girth, z)
    pattern = pattern_girth(sizes, z, bottom, height, mannequin.section_fractions) * (1.0 + options["ease"])
    width = float(np.max(np.maximum(pattern, perimeter + 2.0 * np.pi * MIN_CLEARANCE)))
    columns = 2 * max(6, int(np.ceil(width / (2.0 * edge))))
    clearance = options["clearance"]
    half_x, half_z = (axis_extent(mannequin.rotation, mannequin.semi_axes, axis) for axis in (0, 2))
    neck_parts = [
        i for i, p in enumerate(mannequin.topology) if p.side == "C" and mannequin.center[i, 2] - half_z[i] > z_sh
    ]
    neck = max((float(half_x[i]) for i in neck_parts), default=0.05 * height) + clearance
    z_top = max(float(silhouette_top(mannequin, np.array([neck]))[0]) - clearance, z_sh)
    rows = int(np.ceil((z_top - z_hem) / edge)) + 4  # + the three girth lines
    z_armpit = bottom + mannequin.section_fractions["Br"] * height  # about where the arms end the body tube
    loop = 1 + 2 * max(1, int(np.ceil((z_top - z_armpit) / edge)))  # armhole nodes: armpit, front, back
    sleeve_rows = max(2, int(np.ceil(options["sleeve_length"] * height / edge)) + 1)
    return rows * (columns + 2) + 2 * sleeve_rows * loop


def _defaults(builder):
    import inspect

    return {
        name: p.default
        for name, p in inspect.signature(builder).parameters.items()
        if p.default is not inspect.Parameter.empty
    }
