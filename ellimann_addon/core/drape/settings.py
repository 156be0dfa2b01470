"""Drape settings: :class:`DrapeSettings` (lengths in metres), what Blender's ``drape`` takes, from
``core.settings.DRAPE``, the one table of their defaults, labels and descriptions (the command line's and
``Scene.ellimann_drape``'s)."""

from dataclasses import dataclass

import numpy as np

from ..errors import ElliMannError
from ..settings import DRAPE, EDGE_RANGE, FRAME_RANGE
from .colliders import check_subdivisions

# Cloth size: a drape is refused above MAX_CLOTH_VERTICES (about 4 GB; see BYTES_PER_VERTEX in
# blender/services/drape.py).
MAX_CLOTH_VERTICES = 50_000


@dataclass
class DrapeSettings:
    """Simulation options (defaults: ``DRAPE``). Lengths in metres.

    ``collider``: "pieces" (the convex pieces, ``cushions`` and the subdivision levels say how) or "skin" (the
    mannequin's skin at ``skin_level``, one mesh: ``core.drape.colliders.skin_collider``);

    ``distance``: the cloth's collision distance (it keeps this far from the colliders);
    ``sewing_force``: the sewing springs' force limit (0 would be unbounded, which explodes while
    seams are far apart); ``quality``: solver steps per frame; ``collision_quality``: collision
    passes per step.
    """

    collider: str = DRAPE["collider"].default
    skin_level: str = DRAPE["skin_level"].default
    frames: int = DRAPE["frames"].default
    edge: float = DRAPE["edge"].default
    cushions: bool = DRAPE["cushions"].default
    sphere_subdivisions: int = DRAPE["sphere_subdivisions"].default
    cushion_subdivisions: int = DRAPE["cushion_subdivisions"].default
    quality: int = 5
    collision_quality: int = 3
    distance: float = 0.005
    sewing_force: float = 20.0
    max_vertices: int = MAX_CLOTH_VERTICES  # a larger cloth is refused (see blender/services/drape.py's cloth_size)

    def checked(self):
        for name in ("collider", "skin_level"):
            accepted = DRAPE[name].values
            if getattr(self, name) not in accepted:
                raise ElliMannError(f"{name}: must be one of {', '.join(accepted)}, got {getattr(self, name)!r}")
        if (
            isinstance(self.frames, bool)
            or not isinstance(self.frames, (int, np.integer))
            or not (FRAME_RANGE[0] <= self.frames <= FRAME_RANGE[1])
        ):
            raise ElliMannError(
                f"frames: must be an integer from {FRAME_RANGE[0]} to {FRAME_RANGE[1]}, got {self.frames!r}"
            )
        low, high = EDGE_RANGE
        if isinstance(self.edge, bool) or not isinstance(self.edge, (int, float)) or not low <= self.edge <= high:
            raise ElliMannError(f"edge: the cloth's edge length must be from {low} to {high} m, got {self.edge!r}")
        check_subdivisions("sphere_subdivisions", self.sphere_subdivisions)
        check_subdivisions("cushion_subdivisions", self.cushion_subdivisions)
        if not 1 <= self.quality <= 50:
            raise ElliMannError(f"quality: must be from 1 to 50 steps per frame, got {self.quality!r}")
        if not 1 <= self.collision_quality <= 20:
            raise ElliMannError(f"collision_quality: must be from 1 to 20 passes, got {self.collision_quality!r}")
        if not 0.001 <= self.distance <= 0.05:
            raise ElliMannError(f"distance: must be from 0.001 to 0.05 m, got {self.distance!r}")
        if (
            isinstance(self.max_vertices, bool)
            or not isinstance(self.max_vertices, (int, np.integer))
            or self.max_vertices < 100
        ):
            raise ElliMannError(f"max_vertices: must be an integer of at least 100, got {self.max_vertices!r}")
        return self
