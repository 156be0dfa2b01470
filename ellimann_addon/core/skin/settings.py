"""How a skin is made: its voxel (a preview and a final level, or any size in between), how wide neighbours
blend, and the checks that refuse a skin before any work (a voxel too fine for memory, pieces too thin for it).
``core.settings.SKIN`` is the one table of the options (the command line's and the panels')."""

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ElliMannError
from ..geometry.ellipsoid import bounds
from ..mannequin.skin_record import SKIN_VERSION
from ..settings import BLEND_RANGE, DEFAULT_BLEND, LEVELS, VOXEL_RANGE_MM

BYTES_PER_NODE = 40  # the field's grid: its values, the marks and the meshing's temporaries (measured, 5 mm)
MAX_BYTES = 4 * 1024**3  # a skin that would need more is refused before any work
THIN = 1.5  # a piece must be this many voxels thick (twice its smallest semi-axis) or it may vanish or tear


@dataclass(frozen=True)
class SkinSettings:
    """A skin's voxel (mm) and blend (times the thinner piece's smallest semi-axis)."""

    voxel_mm: float = LEVELS["final"]
    blend: float = DEFAULT_BLEND

    def __post_init__(self):
        for name, value, (low, high) in (
            ("skin_voxel", self.voxel_mm, VOXEL_RANGE_MM),
            ("skin_blend", self.blend, BLEND_RANGE),
        ):
            number = isinstance(value, (int, float)) and not isinstance(value, bool)
            if not number or not math.isfinite(value) or not low <= value <= high:
                raise ElliMannError(f"{name}: must be a number from {low:g} to {high:g}, got {value!r}")

    @classmethod
    def at_level(cls, level, voxel_mm=None, blend=DEFAULT_BLEND):
        """The settings of a level ("preview", "final"), its voxel replaced by ``voxel_mm`` if given."""
        if level not in LEVELS:
            raise ElliMannError(f"skin_level: must be one of {', '.join(LEVELS)}, got {level!r}")
        return cls(LEVELS[level] if voxel_mm is None else voxel_mm, blend)

    @property
    def voxel(self):
        """The voxel in metres."""
        return self.voxel_mm / 1000.0

    def to_dict(self):
        """The ``skin`` section of a mannequin file: how its skin was made, so that it can be made again."""
        return {"version": SKIN_VERSION, "voxel_mm": self.voxel_mm, "blend": self.blend, "method": METHOD}

    @classmethod
    def from_dict(cls, data):
        if not isinstance(data, dict) or data.get("version") != SKIN_VERSION:
            raise ElliMannError(f"skin: must be an object with version {SKIN_VERSION}, voxel_mm and blend")
        try:
            return cls(float(data["voxel_mm"]), float(data["blend"]))
        except (KeyError, TypeError, ValueError):
            raise ElliMannError("skin: voxel_mm and blend must be numbers") from None


METHOD = (
    "signed-distance bound of each ellipsoid; neighbours in the body blended by the polynomial smooth minimum "
    "(width: blend times the thinner piece's smallest semi-axis, at most 4 cm), the blends joined by a 4-norm; "
    "pieces that do not touch, one off the trunk, kept 1.25 voxels apart unless that leaves more handles or "
    "parts the body; "
    "marching cubes with a watertight table"
)


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
