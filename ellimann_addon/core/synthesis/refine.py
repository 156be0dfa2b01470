"""Exact mode: deform an interpolated mannequin gently until its m_T matches the request (quasi-Newton on five
factors; see ``core.synthesis.synthesize`` for the method)."""

from dataclasses import dataclass, fields

import numpy as np

from ..constants import CM_PER_M, GIRTHS, SECTION_FRACTIONS
from ..geometry.ellipsoid import axis_extent, section_extent
from ..geometry.section_hull import HullStructure
from ..measure.tailor import followed_measurements, section_heights, tailor_measurements
from ..measurements import MEASUREMENTS

# Exact mode.
EXACT_TOLERANCE = 1e-5  # relative m_T error at which refinement stops (0.001 %)
EXACT_MAX_ITERATIONS = 12
_JACOBIAN_REFRESH = 4  # Broyden steps before a slow mannequin gets a fresh finite-difference Jacobian
FACTOR_LIMITS = (0.75, 4.0 / 3.0)  # the refinement never scales beyond these (it would show)
_MAX_STEP = 0.1  # largest change of a log factor per Newton step
_FD_STEP = 1e-4  # log-factor step of the finite-difference Jacobian
_TIKHONOV = 1e-10  # keeps the Newton system solvable when a measurement does not respond
_TAPER = 1.0  # how strongly a section's factor lengthens the parts it cuts off their middle
_DAMPING = 1e-3  # initial Levenberg-Marquardt damping (relative to each factor's own curvature)
# A step from further than this (the largest |log m_T - log target|) is measured by following the girth sections'
# structure (core.measure.tailor.followed_measurements), as it is rarely the last; a step from nearer, exactly.
_FOLLOW_ABOVE = 1e-3
_GIRTH_KNOT = {"Hi": 1, "Wa": 2, "Br": 3}
_INDEX = {key: i for i, key in enumerate(MEASUREMENTS)}


@dataclass
class _DeformBasis:
    """What the deformation needs from the unrefined geometry (held fixed while factors change)."""

    bottom: np.ndarray  # (B,) m
    shoulder_half: np.ndarray  # (B,) m, half of Sh
    girth_weight: np.ndarray  # (B, n, 3) hat weight of each part for Br, Wa, Hi (GIRTHS order)
    origin_y: np.ndarray  # (B, n) y of the vertical axis the girth scaling is about, at each part
    vertical: np.ndarray  # (B, n, 3) share of each local axis along world z (R[2, k]^2)
    lateral: np.ndarray  # (B, n, 3) share along world x
    taper: np.ndarray  # (B, n, 3) how far off its middle each girth part is cut by Br, Wa, Hi (0..1)
    anchor: np.ndarray  # (B, n, 3) z of the end of the part farther from each section
    shoulder_scaled: np.ndarray  # (n,) parts that widen with Sh
    shoulder_carried: np.ndarray  # (n,) parts moved sideways with Sh (arms)
    fractions: dict  # the section heights m_T measures at (the reference set's)

    _SHARED = ("shoulder_scaled", "shoulder_carried", "fractions")  # per part or set, not per mannequin

    def take(self, rows):
        if len(rows) == len(self.bottom) and np.array_equal(rows, np.arange(len(rows))):
            return self  # every mannequin in order (deform only reads the basis)
        return _DeformBasis(
            **{
                f.name: getattr(self, f.name) if f.name in self._SHARED else getattr(self, f.name)[rows]
                for f in fields(self)
            }
        )

    def tile(self, count):
        def rep(a):
            return np.tile(a, (count,) + (1,) * (a.ndim - 1))

        return _DeformBasis(
            **{
                f.name: getattr(self, f.name) if f.name in self._SHARED else rep(getattr(self, f.name))
                for f in fields(self)
            }
        )


def _knots(fractions):
    """Knots of the girth blend's hat functions, in fractions of He: full effect at a section, none beyond the
    neighbouring knots. Below the hip section the blend fades over the thighs, above the breast over the upper
    chest (as far above Br as Wa is below it)."""
    hi, wa, br = fractions["Hi"], fractions["Wa"], fractions["Br"]
    return (hi - (wa - hi), hi, wa, br, br + (br - wa))


def _hats(fraction, knots):
    """The piecewise-linear hats over ``knots`` of Br, Wa and Hi (GIRTHS order) at ``fraction``, stacked last: each 1
    at its knot, 0 at the neighbouring knots and beyond."""
    knots = np.asarray(knots, dtype=float)
    rising = [(fraction - knots[i]) * (1.0 / (knots[i + 1] - knots[i])) for i in range(len(knots) - 1)]
    return np.stack(
        [np.maximum(np.minimum(rising[_GIRTH_KNOT[key] - 1], 1.0 - rising[_GIRTH_KNOT[key]]), 0.0) for key in GIRTHS],
        axis=-1,
    )


# Points across an ellipsoid's height (in half-extents) and their weights, proportional to the area
# of the horizontal section there (1 - t^2): the blend weight of a part is the hat averaged over it.
_SPAN = np.linspace(-1.0, 1.0, 9)[1:-1]
_SPAN_WEIGHT = (1.0 - _SPAN**2) / np.sum(1.0 - _SPAN**2)


def deform_basis(topology, rotation, center, semi_axes, measured, fractions=None):
    fractions = fractions or SECTION_FRACTIONS
    knots = _knots(fractions)
    bottom, height, z = section_heights(rotation, center, semi_axes, fractions)
    half_z = axis_extent(rotation, semi_axes, 2)  # (B, n)
    girth = topology.girth_mask
    parts = np.nonzero(girth)[0]
    # The blend weights of the girth parts (the others have none).
    span = center[:, parts, 2, None] + half_z[:, parts, None] * _SPAN  # (B, p, q)
    fraction = (span - bottom[:, None, None]) / height[:, None, None]
    weight = np.zeros(center.shape[:-1] + (len(GIRTHS),))
    hats = _hats(fraction, knots)  # (B, p, q, 3)
    weight[:, parts] = sum(hats[:, :, q] * w for q, w in enumerate(_SPAN_WEIGHT))  # in a fixed order, as _dot
    fraction = (center[..., 2] - bottom[:, None]) / height[:, None]
    # Each girth section's own centre in y (middle of its extent), interpolated between sections.
    sections = np.stack([z[key] for key in GIRTHS], axis=-1)  # (B, 3)
    middle, half, hit = section_extent(
        rotation[:, None, parts], center[:, None, parts], semi_axes[:, None, parts], sections[:, :, None], 1
    )
    top = np.where(hit, middle + half, -np.inf).max(axis=-1, initial=-np.inf)
    low = np.where(hit, middle - half, np.inf).min(axis=-1, initial=np.inf)
    centre_y = np.where(np.isfinite(top), 0.5 * (top + low), 0.0)  # (B, 3) in GIRTHS order: Br, Wa, Hi
    order = [GIRTHS.index(key) for key in ("Hi", "Wa", "Br")]
    heights = [fractions[key] for key in ("Hi", "Wa", "Br")]
    origin_y = _interp_rows(fraction, heights, centre_y[:, order])
    # Where each section cuts each girth part, relative to the part's middle (-1 bottom .. 1 top).
    cut = (sections[:, None, :] - center[..., 2, None]) / half_z[..., None]  # (B, n, 3)
    distance = np.abs(cut)
    taper = np.where((distance < 1.0) & girth[:, None], distance, 0.0)
    anchor = center[..., 2, None] - np.sign(cut) * half_z[..., None]
    depends_sh = topology.dependency_mask[:, _INDEX["Sh"]]
    return _DeformBasis(
        bottom=bottom,
        shoulder_half=0.5 * measured[:, _INDEX["Sh"]] / CM_PER_M,
        girth_weight=weight,
        origin_y=origin_y,
        vertical=rotation[..., 2, :] ** 2,
        lateral=rotation[..., 0, :] ** 2,
        taper=taper,
        anchor=anchor,
        shoulder_scaled=depends_sh & girth,
        shoulder_carried=depends_sh & ~girth,
        fractions=fractions,
    )


def _interp_rows(x, knots, values):
    """np.interp(x[b], knots, values[b]) for every row b at once: x (B, n), knots (K,) increasing, values (B, K);
    constant beyond the first and last knot."""
    out = np.broadcast_to(values[:, :1], x.shape).copy()
    for j in range(len(knots) - 1):
        slope = (values[:, j + 1] - values[:, j]) / (knots[j + 1] - knots[j])
        inside = x > knots[j]
        part = values[:, j, None] + slope[:, None] * (np.minimum(x, knots[j + 1]) - knots[j])
        out = np.where(inside, part, out)
    return out


def deform(basis, center, semi_axes, factors):
    """Apply refinement factors (B, 5) (He, Sh, Br, Wa, Hi; 1 = unchanged) -> (center, semi_axes).

    Rotations are unchanged. Symmetric about x = 0 by construction.
    """
    f = np.asarray(factors, dtype=float)
    center = center.copy()
    semi = semi_axes.copy()
    girth_f = f[:, [_INDEX[key] for key in GIRTHS]]  # (B, 3)
    # Br, Wa, Hi, first: a part cut by a section away from its middle is lengthened or shortened
    # from its far end, which widens or narrows it there much more than in its middle (a rib cage
    # ending higher narrows the waist, not the bust).
    for g in range(len(GIRTHS)):
        taper = basis.taper[..., g]
        v = girth_f[:, g, None] ** (_TAPER * taper)  # (B, n), exactly 1 where the section cuts no part
        anchor = basis.anchor[..., g]
        center[..., 2] = anchor + v * (center[..., 2] - anchor)
        cut = np.nonzero(taper.any(axis=0))[0]  # elsewhere the semi-axes would be multiplied by exactly 1
        semi[:, cut] *= 1.0 + (v[:, cut, None] - 1.0) * basis.vertical[:, cut]
    # He: vertical stretch about the floor.
    he = f[:, _INDEX["He"], None]
    center[..., 2] = basis.bottom[:, None] + he * (center[..., 2] - basis.bottom[:, None])
    semi *= 1.0 + (he[..., None] - 1.0) * basis.vertical
    # Br, Wa, Hi: horizontal scaling blended with height.
    sigma = 1.0 + _dot(basis.girth_weight, (girth_f - 1.0)[:, None, :])
    center[..., 0] *= sigma
    center[..., 1] = basis.origin_y + sigma * (center[..., 1] - basis.origin_y)
    semi *= 1.0 + (sigma[..., None] - 1.0) * (1.0 - basis.vertical)
    # Sh: the shoulders widen along x; the arms hanging from them move out with their edge.
    sh = f[:, _INDEX["Sh"], None]
    scaled = np.nonzero(basis.shoulder_scaled)[0]
    center[:, scaled, 0] *= sh
    semi[:, scaled] *= 1.0 + (sh[..., None] - 1.0) * basis.lateral[:, scaled]
    carried = np.nonzero(basis.shoulder_carried)[0]
    shift = np.zeros(center.shape[:-1])  # added to every part, as 0 to the others (-0 becomes 0)
    shift[:, carried] = np.sign(center[:, carried, 0]) * (sh - 1.0) * basis.shoulder_half[:, None]
    center[..., 0] += shift
    return center, semi


@dataclass
class Refinement:
    center: np.ndarray
    semi_axes: np.ndarray
    measured: np.ndarray  # (B, 5) cm, m_T of the refined mannequins
    factors: np.ndarray  # (B, 5) the deformation factors found (1 = unchanged)
    iterations: int
    converged: np.ndarray  # (B,) bool: every measurement within the tolerance


def _girth_sections(rows):
    """The rows of the girth sections of mannequins ``rows`` in followed_measurements' structure."""
    return (len(GIRTHS) * np.asarray(rows)[:, None] + np.arange(len(GIRTHS))).ravel()


def refine(
    topology,
    rotation,
    center,
    semi_axes,
    targets,
    measured=None,
    tolerance=EXACT_TOLERANCE,
    max_iterations=EXACT_MAX_ITERATIONS,
    jacobian=None,
    fractions=None,
    structure=None,
):
    """Deform mannequins (B, n, ...) so that m_T matches ``targets`` (B, 5) cm (exact mode).

    Solves r(x) = log m_T(deform(exp x)) - log target = 0 for the log factors x, Levenberg-Marquardt
    style: starting from ``jacobian`` ((5, 5) or (B, 5, 5), e.g. ``ReferenceSet.refine_jacobian``)
    or, without one, a forward-difference Jacobian (5 m_T per mannequin); Broyden updates after
    every step (one m_T each), a step kept only if it lowers |r| (else more damping), a
    forward-difference Jacobian if a mannequin is slow to converge. The result is never further from
    the request than the IDW mannequin it starts from. All batched; mannequins already within
    ``tolerance`` are returned unchanged. ``fractions``: the section heights m_T measures at (the reference
    set's; default SECTION_FRACTIONS). ``measured`` and ``structure``: m_T of the start and where its girth
    sections' outermost pieces change (``core.measure.tailor.followed_measurements``), when the caller has them.

    The steps far from the target are measured by following the girth sections' structure from the step before
    (cheaper; exact as long as no hidden piece surfaces); whatever a mannequin's last measurement, the one
    returned, and the convergence it shows, is m_T's. A step that fails to lower |r| never ends the search on a
    followed measurement: the mannequin it was judged against is measured exactly, and its later steps too (a wrong
    followed value kept as the one to beat would fail every step after it; issue 26).
    """
    girth = topology.girth_mask
    targets = np.atleast_2d(np.asarray(targets, dtype=float))
    if structure is None:
        start, structure = followed_measurements(rotation, center, semi_axes, girth, fractions)
        measured = start if measured is None else measured
    basis = deform_basis(topology, rotation, center, semi_axes, measured, fractions)
    count = len(MEASUREMENTS)
    x = np.zeros((len(targets), count))
    current = measured.copy()
    exact = np.ones(len(targets), dtype=bool)  # current[b] is m_T's, not a followed measurement
    trusted = np.ones(len(targets), dtype=bool)  # its steps may follow the structure (until that once misled it)
    residual = np.log(np.maximum(current, 1e-12) / targets)
    if jacobian is None:
        jacobian = np.zeros((len(targets), count, count))
        age = np.full(len(targets), -1)  # steps since the Jacobian was computed (-1: never)
    else:
        jacobian = np.broadcast_to(np.asarray(jacobian, dtype=float), (len(targets), count, count)).copy()
        age = np.zeros(len(targets), dtype=int)
    damping = np.full(len(targets), _DAMPING)
    # A factor that reaches FACTOR_LIMITS is frozen there and its measurement left as close as that
    # allows; the other factors keep solving their own measurements (no trading one for another).
    free = np.ones((len(targets), count), dtype=bool)
    out_center, out_semi = center.copy(), semi_axes.copy()
    lo, hi = np.log(FACTOR_LIMITS)
    eye = np.eye(count)
    iterations = 0
    while True:
        todo = np.nonzero((np.abs(residual) * free).max(axis=1) > tolerance)[0]
        if not len(todo) or iterations == max_iterations:
            # Done as far as the last measurements tell: those that followed a structure are measured now.
            unsure = np.nonzero(~exact)[0]
            if not len(unsure):
                break
            current[unsure] = tailor_measurements(
                rotation[unsure], out_center[unsure], out_semi[unsure], girth, basis.fractions
            )
            residual[unsure] = np.log(np.maximum(current[unsure], 1e-12) / targets[unsure])
            exact[unsure] = True
            continue
        iterations += 1
        stale = todo[(age[todo] < 0) | (age[todo] >= _JACOBIAN_REFRESH)]
        for rows in (stale[trusted[stale]], stale[~trusted[stale]]):
            if len(rows):
                jacobian[rows] = fd_jacobian(
                    basis,
                    rows=rows,
                    rotation=rotation,
                    center=center,
                    semi_axes=semi_axes,
                    x=x,
                    base=np.log(np.maximum(current[rows], 1e-12)),
                    girth=girth,
                    structure=structure.take(_girth_sections(rows)) if trusted[rows[0]] else None,
                )
        age[stale] = 0
        j = jacobian[todo]
        mask = free[todo]
        reduced = j * mask[:, :, None] * mask[:, None, :]
        rt = np.swapaxes(reduced, -1, -2)
        normal = _dot(rt[:, :, None, :], rt[:, None, :, :])  # J^T J
        scale = np.diagonal(normal, axis1=-2, axis2=-1) + _TIKHONOV  # Marquardt: each factor by its own scale
        system = normal + (damping[todo, None] * scale + ~mask)[..., None] * eye
        step = -_solve_positive(system, _dot(rt, (residual[todo] * mask)[:, None, :]))
        wanted = x[todo] + np.clip(step, -_MAX_STEP, _MAX_STEP)
        new_x = np.clip(wanted, lo, hi)
        c, d = deform(basis.take(todo), center[todo], semi_axes[todo], np.exp(new_x))
        follow = (np.abs(residual[todo]).max(axis=1) > _FOLLOW_ABOVE) & trusted[todo]
        m = np.empty((len(todo), count))
        found = [None, None]
        for followed in (False, True):
            rows = np.nonzero(follow == followed)[0]
            if len(rows):
                warm = structure.take(_girth_sections(todo[rows])) if followed else None
                m[rows], found[followed] = followed_measurements(
                    rotation[todo[rows]], c[rows], d[rows], girth, basis.fractions, warm=warm
                )
        new_residual = np.log(np.maximum(m, 1e-12) / targets[todo])
        # Broyden: the secant of this step corrects the Jacobian along the step, kept or not.
        dx = new_x - x[todo]
        norm = _dot(dx, dx)
        miss = new_residual - residual[todo] - _dot(j, dx[:, None, :])
        jacobian[todo] = j + np.divide(
            miss[:, :, None] * dx[:, None, :], norm[:, None, None], out=np.zeros_like(j), where=norm[:, None, None] > 0
        )
        age[todo] += 1
        better = _dot(new_residual * mask, new_residual * mask) < _dot(residual[todo] * mask, residual[todo] * mask)
        damping[todo] = np.where(better, damping[todo] / 3.0, damping[todo] * 4.0)
        keep = todo[better]
        x[keep], residual[keep], current[keep] = new_x[better], new_residual[better], m[better]
        out_center[keep], out_semi[keep] = c[better], d[better]
        exact[keep] = ~follow[better]
        for followed in (False, True):
            rows = np.nonzero(follow == followed)[0]
            kept = better[rows]
            if kept.any():
                structure = structure.replaced(
                    _girth_sections(todo[rows][kept]), found[followed].take(_girth_sections(np.nonzero(kept)[0]))
                )
        free[keep] &= new_x[better] == wanted[better]
        # A step judged against a followed measurement may have failed only because that measurement was wrong (a
        # hidden piece has surfaced since): the mannequin is measured exactly, and its steps from then on too.
        recheck = todo[~better & ~exact[todo]]
        if len(recheck):
            current[recheck], found_now = followed_measurements(
                rotation[recheck], out_center[recheck], out_semi[recheck], girth, basis.fractions
            )
            residual[recheck] = np.log(np.maximum(current[recheck], 1e-12) / targets[recheck])
            exact[recheck], trusted[recheck] = True, False
            structure = structure.replaced(_girth_sections(recheck), found_now)
    converged = np.abs(residual).max(axis=1) <= tolerance
    return Refinement(out_center, out_semi, current, np.exp(x), iterations, converged)


def _dot(a, b):
    """Sum over the last axis (the same length in both) of a * b (the other axes broadcast), in a fixed order:
    unlike a matrix product or einsum, whose order can depend on the array's size and alignment, a mannequin gets
    the same bits alone as in a batch."""
    total = a[..., 0] * b[..., 0]  # already of the broadcast shape
    for k in range(1, a.shape[-1]):
        total += a[..., k] * b[..., k]
    return total


def _solve_positive(system, rhs):
    """x with system x = rhs for stacks of symmetric positive definite (T, f, f) and (T, f): Cholesky, in a fixed
    order (LAPACK's pivoting and blocking could differ between a batch and one system alone)."""
    count = system.shape[-1]
    factor = np.zeros_like(system)
    for j in range(count):  # column by column: each entry's sum in the same order as entry by entry
        total = system[:, j:, j] - _dot(factor[:, j:, :j], factor[:, j, None, :j]) if j else system[:, j:, j].copy()
        factor[:, j, j] = np.sqrt(total[:, 0])
        factor[:, j + 1 :, j] = total[:, 1:] / factor[:, j, j, None]
    y = np.zeros_like(rhs)
    for i in range(count):
        y[:, i] = (rhs[:, i] - (_dot(factor[:, i, :i], y[:, :i]) if i else 0.0)) / factor[:, i, i]
    x = np.zeros_like(rhs)
    for i in reversed(range(count)):
        later = slice(i + 1, count)
        x[:, i] = (y[:, i] - (_dot(factor[:, later, i], x[:, later]) if i + 1 < count else 0.0)) / factor[:, i, i]
    return x


def fd_jacobian(basis, rows, rotation, center, semi_axes, x, base, girth, structure=None):
    """d log m_T / d log factor (T, measurement, factor) by forward differences at x[rows]; with ``structure`` (of
    the mannequins ``rows`` at x) the probes' girths follow it."""
    count = len(MEASUREMENTS)
    probes = np.concatenate([x[rows] + _FD_STEP * np.eye(count)[j] for j in range(count)])
    c, d = deform(
        basis.take(rows).tile(count),
        np.tile(center[rows], (count, 1, 1)),
        np.tile(semi_axes[rows], (count, 1, 1)),
        np.exp(probes),
    )
    tiled = np.tile(rotation[rows], (count, 1, 1, 1))
    if structure is None:
        m = tailor_measurements(tiled, c, d, girth, basis.fractions)
    else:
        m = followed_measurements(
            tiled, c, d, girth, basis.fractions, warm=HullStructure.concatenate([structure] * count)
        )[0]
    m = np.log(np.maximum(m, 1e-12)).reshape(count, len(rows), count)
    return np.moveaxis((m - base[None]) / _FD_STEP, 0, -1)
