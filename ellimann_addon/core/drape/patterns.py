"""What the garments are made of (``core.drape.garments``, ``core.drape.t_shirt``): the Garment mesh, pattern sizes,
body rings (convex hulls of the horizontal sections, offset outward), grids of faces, and :func:`clear_of`."""

from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import ElliMannError, MeasurementError
from ..geometry.ellipsoid import section_at_height
from ..measure.tailor import hull_perimeter, section_heights
from ..measurements import MEASUREMENTS
from .fit_metrics import ellipsoid_signed_distance

MIN_CLEARANCE = 0.005  # m, least initial gap between garment and body
RING_SAMPLES = 512  # support directions per ring before resampling to the garment's resolution


@dataclass
class Garment:
    """A garment mesh: vertices (V, 3) m, faces (F, 3), seams (S, 2) vertex pairs to sew.

    ``panel`` gives each vertex's panel index into ``panel_names``; ``pattern`` the pattern
    sizes in cm and the options used; ``pins`` the vertices a simulation should hold in place
    (the tube dress' top edge, standing in for the elastic band that keeps a strapless dress up).
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    seams: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=int))
    panel: np.ndarray = None
    panel_names: tuple = ()
    pattern: dict = field(default_factory=dict)
    pins: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))


# ----------------------------------------------------------------------------------------------
# Inputs


def pattern_measurements(mannequin, measurements=None):
    """The measurements (cm) a pattern is cut from: m_T (None), the target ("target") or a dict."""
    if measurements is None:
        values = mannequin.measure()
    elif isinstance(measurements, str) and measurements == "target":
        if not mannequin.measurements:
            raise MeasurementError(
                "measurements",
                "the mannequin has no target measurements; use its m_T (measurements=None) or pass a dict in cm",
            )
        values = mannequin.measurements
    elif isinstance(measurements, dict):
        values = measurements
    else:
        raise MeasurementError("measurements", "must be None (m_T), 'target' or a dict of cm values")
    out = {}
    for key in MEASUREMENTS:
        value = values.get(key)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value) or value <= 0:
            raise MeasurementError(key, f"must be a positive number of cm, got {value!r}")
        out[key] = float(value)
    return out


def check_range(name, value, low, high):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (low <= value <= high):
        raise ElliMannError(f"{name}: must be a number from {low} to {high}, got {value!r}")
    return float(value)


# ----------------------------------------------------------------------------------------------
# Rings: offset convex hulls of horizontal body sections


def section_ellipses(mannequin, mask, heights):
    """Section ellipses of the masked parts at each height: centre (Z, n, 2), k (Z, n, 2, 2), active (Z, n)."""
    r, c, d = mannequin.rotation[mask], mannequin.center[mask], mannequin.semi_axes[mask]
    heights = np.asarray(heights, dtype=float)[:, None]
    centre, k, hit = section_at_height(r[None], c[None], d[None], heights)
    return centre, k, hit


def hull_rings(centre, k, active, offset, samples=RING_SAMPLES):
    """Offset hull boundaries sampled in ``samples`` outward directions theta = 2 pi m / samples.

    Returns (Z, samples, 2): for each direction the support point of the outermost section ellipse
    plus ``offset`` (Z,) along the direction. Consecutive points across a change of ellipse span
    the hull's straight bridges, so the polygon is the offset hull up to the sampling.
    """
    theta = np.arange(samples) * (2.0 * np.pi / samples)
    u = np.stack([np.cos(theta), np.sin(theta)], axis=-1)  # (M, 2)
    offset = np.broadcast_to(np.asarray(offset, dtype=float), (len(centre),))
    out = np.empty((len(centre), samples, 2))
    step = 32  # rings per block: the (rings, n, M, 2) temporaries stay small
    for start in range(0, len(centre), step):
        c, kk, act = centre[start : start + step], k[start : start + step], active[start : start + step]
        ku = np.einsum("znij,mj->znmi", kk, u)  # (Z, n, M, 2)
        quad = np.sqrt(np.clip(np.einsum("znmi,mi->znm", ku, u), 1e-30, None))
        h = np.where(act[:, :, None], np.einsum("zni,mi->znm", c, u) + quad, -np.inf)
        win = np.argmax(h, axis=1)  # (Z, M)
        zi = np.arange(len(c))[:, None]
        mi = np.arange(samples)[None, :]
        point = c[zi, win] + ku[zi, win, mi] / quad[zi, win, mi][..., None]
        out[start : start + step] = point + offset[start : start + step, None, None] * u[None]
    return out


def resample_polyline(polyline, count, closed):
    """``count`` points evenly spaced by arc length along a polyline (closed: a loop from its first point)."""
    pts = np.concatenate([polyline, polyline[:1]]) if closed else polyline
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    target = np.linspace(0.0, s[-1], count, endpoint=not closed)
    return np.stack([np.interp(target, s, pts[:, i]) for i in range(pts.shape[1])], axis=-1)


def fill_gaps(centre, k, active):
    """Rings whose plane cuts no part take the sections of the nearest ring that has some.

    Between two parts that do not overlap (a torso with a gap at the hips, the elbow between an
    upper arm and a forearm that only their cushion joins) the garment then stays a straight tube.
    Returns None if no ring cuts anything.
    """
    covered = active.any(axis=1)
    if not covered.any():
        return None
    if covered.all():
        return centre, k, active
    rows = np.nonzero(covered)[0]
    nearest = rows[np.argmin(np.abs(np.arange(len(covered))[:, None] - rows[None]), axis=1)]
    return centre[nearest], k[nearest], active[nearest]


def girth_perimeters(mannequin, mask, heights):
    sections = fill_gaps(*section_ellipses(mannequin, mask, heights))
    if sections is None:
        raise ElliMannError("mannequin: no girth ellipsoid at the garment's heights")
    return hull_perimeter(*sections), sections


def grid_faces(rows, cols, closed):
    """Triangles of a rows x cols node grid (row-major); ``closed`` wraps the columns into a tube.

    Quads alternate their diagonal so the cloth has no preferred shear direction.
    """
    c_count = cols if closed else cols - 1
    r, c = np.meshgrid(np.arange(rows - 1), np.arange(c_count), indexing="ij")
    r, c = r.ravel(), c.ravel()
    c1 = (c + 1) % cols
    a, b = r * cols + c, r * cols + c1
    d, e = (r + 1) * cols + c, (r + 1) * cols + c1
    flip = (r + c) % 2 == 1
    first = np.where(flip[:, None], np.stack([a, b, d], 1), np.stack([a, b, e], 1))
    second = np.where(flip[:, None], np.stack([b, e, d], 1), np.stack([a, e, d], 1))
    return np.concatenate([first, second])


def body_extent(mannequin):
    bottom, height, _ = section_heights(mannequin.rotation, mannequin.center, mannequin.semi_axes)
    return float(bottom), float(height)


def clear_rows(mannequin, rings):
    """How many rings (rows, cols, 3), counted from the first, keep half MIN_CLEARANCE from every part."""
    gap = (
        ellipsoid_signed_distance(rings.reshape(-1, 3), mannequin.rotation, mannequin.center, mannequin.semi_axes)
        .min(axis=1)
        .reshape(len(rings), -1)
        .min(axis=1)
    )
    bad = np.nonzero(gap < 0.5 * MIN_CLEARANCE)[0]
    return int(bad[0]) if len(bad) else len(rings)


def clear_of(garment, distance, clearance=0.5 * MIN_CLEARANCE, iterations=12, step=1e-3):
    """The garment with every vertex moved to at least ``clearance`` (m) outside a body (by default
    the least gap the builders leave to the ellipsoids).

    ``distance(points (P, 3)) -> (P,)`` is the body's signed distance (negative inside), e.g.
    ``lambda p: BodyPieces(m, cushions=True).signed_distance(p)[0]``. Vertices closer than
    ``clearance`` move along the distance's gradient (central differences of ``step``) by what they
    lack, a few rounds until none is left; the rest stay put. ``pattern["cleared"]`` counts the
    moved vertices. Raises ElliMannError if some stay too close (a body the garment cannot wrap).
    """
    vertices = np.array(garment.vertices, dtype=float)
    moved = np.zeros(len(vertices), dtype=bool)
    for _ in range(iterations):
        gap = np.asarray(distance(vertices), dtype=float)
        close = np.nonzero(gap < clearance)[0]
        if not len(close):
            break
        p = vertices[close]
        gradient = np.stack(
            [(np.asarray(distance(p + step * e)) - np.asarray(distance(p - step * e))) / (2 * step) for e in np.eye(3)],
            axis=1,
        )
        gradient /= np.maximum(np.linalg.norm(gradient, axis=1, keepdims=True), 1e-12)
        # A little beyond the clearance: the gradient of a union is only piecewise smooth.
        vertices[close] += (clearance - gap[close] + 0.1 * clearance)[:, None] * gradient
        moved[close] = True
    else:
        if np.any(np.asarray(distance(vertices)) < clearance):
            raise ElliMannError(
                f"garment: some vertices of the {garment.name} cannot be moved {clearance} m clear of the body"
            )
    return replace(garment, vertices=vertices, pattern={**garment.pattern, "cleared": int(moved.sum())})
