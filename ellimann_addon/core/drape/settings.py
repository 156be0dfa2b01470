"""Drape settings: :class:`DrapeSettings` (lengths in metres), what Blender's ``drape`` takes, and ``DRAPE``, the
one table of their defaults, labels and descriptions (the command line's and ``Scene.ellimann_drape``'s)."""

from dataclasses import dataclass

import numpy as np

from ..constants import COLLIDER_LEVELS
from ..errors import ElliMannError
from ..option_table import Choice, Option
from .colliders import check_subdivisions
from .garments import EDGE_RANGE, GARMENTS

FRAME_RANGE = (2, 2000)
# Cloth size: a drape is refused above MAX_CLOTH_VERTICES (about 4 GB; see BYTES_PER_VERTEX in
# blender/services/drape.py).
MAX_CLOTH_VERTICES = 50_000

DRAPE = {
    "garment": Option(
        "Garment",
        "tube_dress",
        "Garment to cut from the mannequin's measurements and drape on it",
        "{choices}",
        choices=tuple(
            Choice(kind, label, description, help) for kind, (_, label, description, help) in GARMENTS.items()
        ),
    ),
    "frames": Option(
        "Frames",
        60,
        "Frames to simulate (from frame 1, at the scene's frame rate)",
        "frames to simulate (default {default}, at 24 fps)",
        limits=FRAME_RANGE,
    ),
    "edge": Option(
        "Cloth Edge",
        0.025,
        "Edge length of the garment's mesh (smaller: finer folds, slower)",
        "edge length of the cloth mesh in cm (default {default_cm:g}; smaller is finer and slower)",
        limits=EDGE_RANGE,
    ),
    "cushions": Option(
        "Cushions",
        True,
        "Collide with the cushions and the ellipsoids not in one (off: every ellipsoid)",
        "collide with the cushions and the ellipsoids not in one; --no-cushions: with every "
        "ellipsoid (default: {default_text})",
    ),
    **{
        f"{what}_subdivisions": Option(
            label,
            2,
            f"Icosphere level of the {pieces} colliders ({COLLIDER_LEVELS[0]}: "
            f"coarsest, {COLLIDER_LEVELS[1]}: finest; triangles = 20 * 4^level)",
            "",
            limits=COLLIDER_LEVELS,
        )
        for what, label, pieces in (
            ("sphere", "Ellipsoid Resolution", "ellipsoid"),
            ("cushion", "Cushion Resolution", "cushion"),
        )
    },
}


def garment_help():
    """``--garment``'s help: each garment's own words, the default marked."""
    option = DRAPE["garment"]
    return " or ".join(
        f"{c.value} ({c.help}{'; default' if c.value == option.default else ''})" for c in option.choices
    )


@dataclass
class DrapeSettings:
    """Simulation options (defaults: ``DRAPE``). Lengths in metres.

    ``distance``: the cloth's collision distance (it keeps this far from the colliders);
    ``sewing_force``: the sewing springs' force limit (0 would be unbounded, which explodes while
    seams are far apart); ``quality``: solver steps per frame; ``collision_quality``: collision
    passes per step.
    """

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
