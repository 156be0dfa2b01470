"""The checks that refuse a skin over the pieces before any work: a voxel too fine for memory, pieces too thin for
it. How a skin is made (its kind, voxel, blend) is ``core.mannequin.skin_record.SkinSettings``; ``core.settings.SKIN``
is the one table of the options (the command line's and the panels')."""

import math

import numpy as np

from ..errors import ElliMannError
from ..geometry.ellipsoid import bounds

BYTES_PER_NODE = 40  # the field's grid: its values, the marks and the meshing's temporaries (measured, 5 mm)
MAX_BYTES = 4 * 1024**3  # a skin that would need more is refused before any work
THIN = 1.5  # a piece must be this many voxels thick (twice its smallest semi-axis) or it may vanish or tear


def grid_nodes(rotation, center, semi_axes, voxel, margin):
    """How many nodes the field's grid has for pieces and a voxel (m) with ``margin`` (m) around them."""
    lo, hi = bounds(rotation, center, semi_axes)
    extent = hi.max(axis=0) - lo.min(axis=0) + 2.0 * margin
    return int(np.prod(np.ceil(extent / voxel) + 1))


def check_skin_size(mannequin, settings, margin):
    """Refuse, before any work, a voxel whose grid would need more than MAX_BYTES (naming the finest that fits)
    or pieces too thin for it (naming them and the voxel that keeps them). Returns the estimated bytes."""
    arrays = (mannequin.rotation, mannequin.center, mannequin.semi_axes)
    size = grid_nodes(*arrays, settings.voxel, margin) * BYTES_PER_NODE
    if size > MAX_BYTES:
        fits = settings.voxel_mm * (size / MAX_BYTES) ** (1.0 / 3.0)
        fits = math.ceil(fits * 10.0) / 10.0
        while grid_nodes(*arrays, fits / 1000.0, margin) * BYTES_PER_NODE > MAX_BYTES:
            fits = round(fits + 0.1, 1)
        raise ElliMannError(
            f"skin_voxel: {settings.voxel_mm:g} mm voxels would need about {size / 1024**3:.1f} GB for this body "
            f"(limit {MAX_BYTES / 1024**3:g} GB): {fits:g} mm or coarser fits"
        )
    thickness = 2.0 * mannequin.semi_axes.min(axis=1)
    thin = np.flatnonzero(thickness < THIN * settings.voxel)
    if len(thin):
        names = ", ".join(f"'{mannequin.topology.names[i]}' ({thickness[i] * 1000:.0f} mm)" for i in thin[:3])
        more = f" and {len(thin) - 3} more" if len(thin) > 3 else ""
        finest = math.floor(thickness.min() / THIN * 10000.0) / 10.0
        raise ElliMannError(
            f"skin_voxel: {names}{more} too thin for {settings.voxel_mm:g} mm voxels (a piece needs "
            f"{THIN:g} voxels across or it may vanish or tear): {finest:g} mm or finer keeps every piece"
        )
    return size
