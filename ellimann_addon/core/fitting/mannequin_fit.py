"""Fitting a whole mannequin inside one body mesh, part by part, from the vertices each part was traced
from (core/mannequin/traces.py): the paper's tracing (Section 2.3.2) repeated on every body of the traced mesh's
topology, so the same vertices trace the same part on each body.

Every left and central part is fitted to its vertices (core/fitting/inscribed.py: a frame from the points, an
ellipsoid inside the body surface moved out by the part's ``depth`` and within the selection's box),
placed to cover the body's volume in its box (more so near the sections of the measurements it
depends on), twice: the second time around the others, valuing the volume no other part covers above
the rest, so parts spread into the gaps between them. The right parts are mirror images.
"""

from dataclasses import dataclass, field

import numpy as np

from ..constants import GIRTHS, SECTION_FRACTIONS
from ..geometry.ellipsoid import to_frame
from ..geometry.frames import mirror_frame
from ..geometry.volume import BodyVolume
from ..mannequin.model import Mannequin
from .body_mesh import surface_walls, vertex_areas, vertex_normals
from .inscribed import cell_share, hull_surface, inscribed_ellipsoid


class BuildCancelledError(Exception):
    """The user stopped the build; nothing was written."""


@dataclass(frozen=True)
class FitConstants:
    """The fit's tuning, the same for every part."""

    section_fractions: dict = field(default_factory=lambda: dict(SECTION_FRACTIONS))
    fill_spacing: float = 0.008  # m: grid sampling each body's volume, which the parts are placed to fill
    fill_passes: int = 2  # placements of every part: the first alone, the others around the rest
    fill_shared: float = 0.25  # what covering volume another part covers too is worth, after the first pass
    # Volume within ``slab`` (fraction of the height) of the section of a measurement a part depends on
    # counts ``slab_weight`` times more: the parts that make a measurement reach the body's outline there.
    slab: float = 0.01
    slab_weight: float = 3.0
    # A girth part stays this far (fraction of the height) above or below every girth section of a
    # measurement it does not depend on, so that each section cuts only parts that follow its
    # measurement in synthesis, with room for the refinement, which may lengthen parts a little.
    section_clearance: float = 0.025


def section_bounds(part, fit, centre, constants):
    """(floor, ceiling) heights (fractions of the body's) a part centred at height ``centre`` may reach:
    clear, by ``section_clearance``, of the girth sections of measurements it does not depend on (if it
    is a girth part) and of the sections in ``fit.clear``; the part's own ``fit.clearance`` if it has one."""
    fractions = constants.section_fractions
    clearance = constants.section_clearance if fit.clearance is None else fit.clearance
    floor, ceiling = -np.inf, np.inf
    keys = [key for key in GIRTHS if key not in part.depends] if part.girth else []
    for key in keys + list(fit.clear):
        if centre > fractions[key]:
            floor = max(floor, fractions[key] + clearance)
        else:
            ceiling = min(ceiling, fractions[key] - clearance)
    return floor, ceiling


def obstacle_indices(trace):
    """The body vertices that must stay outside the part: all but its cavity walls (none for a mitten)."""
    if trace.fit.mitten:
        return np.zeros(0, dtype=int)
    keep = np.ones(trace.vertex_count, dtype=bool)
    keep[trace.cavity] = False
    return np.nonzero(keep)[0]


def fit_mannequin(body, topology, traces, reference=None, kept=None, constants=None, cancel=None, **fields):
    """Fit every part of ``topology`` inside ``body`` (a BodyMesh) to the vertices of ``traces`` ({part
    name: PartTrace}). Returns (mannequin, kept axis index per part).

    Without ``reference`` the frames take their roll from the world axes (the Base Mannequin); with it
    (a mannequin of the same topology, and the ``kept`` axis of each of its parts, or None) each part
    keeps the axis closest to the reference part's kept axis and the reference's roll about it.
    ``cancel``: called between parts, raises BuildCancelledError when it returns True. ``fields``: name, role,
    measurements of the mannequin. The mannequin is measured (m_T) at ``constants.section_fractions``.
    """
    constants = constants or FitConstants()
    spacing = constants.fill_spacing
    areas = vertex_areas(body.vertices, body.faces)
    normals = vertex_normals(body.vertices, body.faces)
    volume = BodyVolume(body.vertices, body.faces).grid(spacing)
    cells = volume.origin + spacing * np.argwhere(volume.inside)  # the body's, then (if any part pays) those round it
    body_cells = len(cells)
    # Parts that pay for covering the outside are placed over the cells round the body too: every cell a part may
    # share (as far out as its depth and half a cell, cell_share's edge) and half a cell more, from an inside centre.
    paying = [trace.fit for trace in traces.values() if _pays_outside(trace.fit)]
    if paying:
        reach = max(fit.depth for fit in paying) + spacing
        ring = _dilated(volume.inside, int(np.ceil(reach / spacing))) & ~volume.inside
        cells = np.concatenate([cells, volume.origin + spacing * np.argwhere(ring)])
    bottom, height = body.vertices[:, 2].min(), np.ptp(body.vertices[:, 2])
    n = len(topology)
    rotation, center, semi_axes = np.tile(np.eye(3), (n, 1, 1)), np.zeros((n, 3)), np.ones((n, 3))
    kept_out = [None] * n
    fitted = [i for i, part in enumerate(topology) if part.side != "R"]
    twins = topology.twin_indices
    covers = np.zeros((n, len(cells)))  # share of each cell inside each part (inscribe.cell_share)
    obstacles = {i: obstacle_indices(traces[topology.names[i]]) for i in fitted}

    def cover(i):
        return cell_share(to_frame(cells, center[i], rotation[i]), semi_axes[i], spacing)

    surfaces = {}  # most parts keep clear of the same surface: sampled once per obstacles, depth and spacing

    def surface(indices, depth, wall_spacing):
        key = (indices.tobytes(), depth, wall_spacing)
        if key not in surfaces:
            surfaces[key] = surface_walls(body.vertices, body.faces, normals, areas, indices, depth, wall_spacing)
        return surfaces[key]

    for round_ in range(constants.fill_passes):
        for i in fitted:
            if cancel is not None and cancel():
                raise BuildCancelledError()
            part = topology.parts[i]
            trace = traces[part.name]
            fit = trace.fit
            idx, walls = trace.vertices, obstacles[i]
            points, weights = body.vertices[idx], areas[idx]
            if fit.inward is not None:
                points = np.concatenate([points, points + np.asarray(fit.inward)])
                weights = np.concatenate([weights, weights])
            ref_rotation = np.eye(3) if reference is None else reference.rotation[i]
            if reference is None:
                match = None if fit.axis is None else np.asarray(fit.axis, dtype=float)
            else:
                match = None if kept[i] is None else reference.rotation[i][:, kept[i]]
            floor, ceiling = section_bounds(
                part, fit, (weights @ points[:, 2] / weights.sum() - bottom) / height, constants
            )
            floor, ceiling = bottom + floor * height, bottom + ceiling * height
            level = None if fit.level is None else bottom + constants.section_fractions[fit.level] * height
            if fit.mitten:
                walls, wall_areas = hull_surface(body.vertices[idx], fit.depth)
            else:
                # the surface moved out by depth: the part may reach that far outside the body
                walls, wall_areas = surface(walls, fit.depth, fit.wall_spacing)
            weight = np.ones(len(cells))
            pays = _pays_outside(fit)
            if round_ or pays:
                rest = np.ones(n, dtype=bool)
                rest[[i, twins[i]]] = False
                others = covers.max(axis=0, where=rest[:, None], initial=0.0)  # shares are >= 0; no copy of covers
            if round_:
                shared = constants.fill_shared if fit.shared is None else fit.shared
                weight = 1.0 + (shared - 1.0) * others
            if pays:  # the outside another part covers already costs nothing more
                weight[body_cells:] = -fit.outside_cost * (1.0 - others[body_cells:])
            for key in part.depends:
                if key in constants.section_fractions and (part.girth or key == "Sh"):
                    near = (
                        np.abs(cells[:, 2] - bottom - constants.section_fractions[key] * height)
                        < constants.slab * height
                    )
                    weight = np.where(near, weight * constants.slab_weight, weight)
            placed_over = len(cells) if pays else body_cells
            rotation[i], center[i], semi_axes[i], kept_out[i] = inscribed_ellipsoid(
                points,
                weights,
                walls,
                wall_areas,
                ref_rotation,
                margin=fit.margin,
                inside_fraction=fit.inside,
                frame=fit.frame,
                match=match,
                floor=floor,
                ceiling=ceiling,
                level=level,
                span=fit.span,
                fill=cells[:placed_over],
                fill_weight=weight[:placed_over],
                fill_spacing=spacing,
                midline=part.side == "C",
            )
            if twins[i] != i:
                rotation[twins[i]], center[twins[i]] = mirror_frame(rotation[i], center[i])
                semi_axes[twins[i]] = semi_axes[i]
            covers[i], covers[twins[i]] = cover(i), cover(twins[i])
    # measured where it was fitted: at the set's section heights
    return Mannequin(
        topology, rotation, center, semi_axes, section_fractions=constants.section_fractions, **fields
    ).check(), [kept_out[twins[i]] if part.side == "R" else kept_out[i] for i, part in enumerate(topology)]


def _pays_outside(fit):
    """Whether a part pays for the outside it covers: a mitten never does (it fills between the fingers)."""
    return bool(fit.outside_cost) and not fit.mitten


def _dilated(mask, cells):
    """``mask`` (a 3-d bool grid) grown by ``cells`` cells every way (a cube of them round each true cell)."""
    for axis in range(3):
        grown = mask.copy()
        for shift in range(1, cells + 1):
            ahead = [slice(None)] * 3
            behind = [slice(None)] * 3
            ahead[axis], behind[axis] = slice(shift, None), slice(None, -shift)
            grown[tuple(ahead)] |= mask[tuple(behind)]
            grown[tuple(behind)] |= mask[tuple(ahead)]
        mask = grown
    return mask
