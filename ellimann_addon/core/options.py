"""The options of ElliMann's two jobs, synthesis and drape: one options object each, one table each.

``SYNTHESIS`` and ``DRAPE`` hold every option's default, label, descriptions and choices; the command line
(argparse choices, defaults and help) and the property groups (EnumProperty items, defaults, descriptions:
``Scene.ellimann_synthesis``, ``Scene.ellimann_drape``) are generated from them, so they cannot disagree.
:class:`SynthesisOptions` (mode, metric, power, normalize, name; keyword-only) and :class:`DrapeSettings`
(lengths in metres) are what the core's ``synthesize`` / ``synthesize_batch`` and Blender's ``drape`` take.
"""

import dataclasses
from dataclasses import dataclass

import numpy as np

from .collision import check_subdivisions
from .constants import COLLIDER_LEVELS
from .errors import ElliMannError
from .garments import EDGE_RANGE, GARMENTS


@dataclass(frozen=True)
class Choice:
    value: str  # what the core and the command line take ("exact"); the panel's item is value.upper()
    label: str  # the panel's item label
    description: str  # the panel's item tooltip
    help: str = ""  # the command line's wording, where it has its own


@dataclass(frozen=True)
class Option:
    label: str  # the panel's property name
    default: object
    description: str  # the panel's tooltip
    help: str  # the command line's --help ({default} is filled in)
    choices: tuple = ()  # Choice, in the core's order
    shown: tuple = ()  # the panel's order of the choices' values (default: the core's)
    limits: tuple = ()  # (low, high) of a number

    @property
    def values(self):
        return tuple(choice.value for choice in self.choices)

    def enum_items(self):
        """EnumProperty items: (VALUE, label, description) in the panel's order."""
        by_value = {choice.value: choice for choice in self.choices}
        return tuple((value.upper(), by_value[value].label, by_value[value].description)
                     for value in (self.shown or self.values))

    @property
    def enum_default(self):
        return self.default.upper()


# ------------------------------------------------------------------------------------------------ synthesis

SYNTHESIS = {
    "mode": Option(
        "Mode", "exact",
        "How the mannequin is made from the Reference Mannequins: IDW alone misses the request by up to a few %; "
        "Exact refines it until m_T matches",
        "exact (default): refine until m_T matches the request; idw: the paper's interpolation alone",
        choices=(Choice("idw", "IDW", "Segmented inverse-distance weighting alone, as in the paper (m_T off by up "
                                      "to a few %)"),
                 Choice("exact", "Exact", "IDW, then a gentle refinement until m_T matches the request to 0.001% "
                                          "(beyond the paper)")),
        shown=("exact", "idw")),
    "metric": Option(
        "Distance", "raw",
        "How IDW measures the distance from the request to each Reference Mannequin's measurements (nearer ones "
        "weigh more)",
        "IDW distance: raw cm as in the paper (default) or normalized by the ranges L",
        choices=(Choice("raw", "cm", "IDW distances in cm, as in the paper: the wide-ranging girths weigh more than "
                                     "He and Sh"),
                 Choice("normalized", "Normalized", "Each measurement divided by its reference range L, so all five "
                                                    "weigh alike"))),
    "power": Option("p", 2.0, "IDW power (the paper uses 2)", "IDW power p (default {default:g})",
                    limits=(0.5, 16.0)),
    "normalize": Option(
        "Interpolate", "proportional",
        "What IDW averages over the Reference Mannequins: their proportions (ElliMann's default, closer to the "
        "request) or their geometry as it is (the paper's Eq. 2.1)",
        "what IDW averages: proportional (default): each part's heights in proportion to He and widths to its own "
        "measurement; height: heights only; none: the RMs' geometry as it is (the paper)",
        choices=(Choice("none", "Geometry (Paper)", "Average the RMs' geometry as it is, as in the paper (Eq. 2.1)"),
                 Choice("height", "Height Proportions", "Average heights in proportion to each RM's He, widths as "
                                                        "they are"),
                 Choice("proportional", "Proportions", "Average each part in proportion to its RM's measurements: "
                                                       "heights to He, widths to the part's own measurement, then "
                                                       "scale to the request")),
        shown=("proportional", "height", "none")),
}
MODES = SYNTHESIS["mode"].values
METRICS = SYNTHESIS["metric"].values
NORMALIZATIONS = SYNTHESIS["normalize"].values
DEFAULT_MODE = SYNTHESIS["mode"].default
DEFAULT_METRIC = SYNTHESIS["metric"].default
DEFAULT_POWER = SYNTHESIS["power"].default
DEFAULT_NORMALIZE = SYNTHESIS["normalize"].default
POWER_LIMITS = SYNTHESIS["power"].limits
PAPER_NORMALIZE = "none"


def _number(value):
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def check_options(mode=DEFAULT_MODE, metric=DEFAULT_METRIC, power=DEFAULT_POWER, normalize=DEFAULT_NORMALIZE):
    if mode not in MODES:
        raise ElliMannError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    if normalize not in NORMALIZATIONS:
        raise ElliMannError(f"normalize must be one of {', '.join(NORMALIZATIONS)}, got {normalize!r}")
    if metric not in METRICS:
        raise ElliMannError(f"metric must be one of {', '.join(METRICS)}, got {metric!r}")
    if not _number(power) or not POWER_LIMITS[0] <= power <= POWER_LIMITS[1]:
        raise ElliMannError(f"power p must be a number in {POWER_LIMITS[0]:g}-{POWER_LIMITS[1]:g}, got {power!r}")


@dataclass(frozen=True, kw_only=True)
class SynthesisOptions:
    """How a request becomes a mannequin (defaults: ``SYNTHESIS``); ``name``: the mannequin's (default: from the
    request, ``ElliMann He-Sh-Br-Wa-Hi``). The paper's method is ``mode="idw", normalize="none"``."""

    mode: str = DEFAULT_MODE
    metric: str = DEFAULT_METRIC
    power: float = DEFAULT_POWER
    normalize: str = DEFAULT_NORMALIZE
    name: str | None = None

    def checked(self):
        check_options(self.mode, self.metric, self.power, self.normalize)
        return self

    def replace(self, **changes):
        return dataclasses.replace(self, **changes)


PAPER = SynthesisOptions(mode="idw", metric="raw", power=2.0, normalize=PAPER_NORMALIZE)


# ------------------------------------------------------------------------------------------------ drape

FRAME_RANGE = (2, 2000)
# Cloth size: a drape is refused above MAX_CLOTH_VERTICES (about 4 GB; see BYTES_PER_VERTEX in
# blender/services/drape.py).
MAX_CLOTH_VERTICES = 50_000

DRAPE = {
    "garment": Option(
        "Garment", "tube_dress", "Garment to cut from the mannequin's measurements and drape on it",
        "{choices}",
        choices=tuple(Choice(kind, label, description, help) for kind, (_, label, description, help)
                      in GARMENTS.items())),
    "frames": Option("Frames", 60, "Frames to simulate (from frame 1, at the scene's frame rate)",
                     "frames to simulate (default {default}, at 24 fps)", limits=FRAME_RANGE),
    "edge": Option("Cloth Edge", 0.025, "Edge length of the garment's mesh (smaller: finer folds, slower)",
                   "edge length of the cloth mesh in cm (default {default_cm:g}; smaller is finer and slower)",
                   limits=EDGE_RANGE),
    "cushions": Option("Cushions", True, "Collide with the cushions and the ellipsoids not in one (off: every "
                                         "ellipsoid)",
                       "collide with the cushions and the ellipsoids not in one; --no-cushions: with every "
                       "ellipsoid (default: {default_text})"),
    **{f"{what}_subdivisions": Option(label, 2, f"Icosphere level of the {pieces} colliders ({COLLIDER_LEVELS[0]}: "
                                                f"coarsest, {COLLIDER_LEVELS[1]}: finest; triangles = 20 * 4^level)",
                                      "", limits=COLLIDER_LEVELS)
       for what, label, pieces in (("sphere", "Ellipsoid Resolution", "ellipsoid"),
                                   ("cushion", "Cushion Resolution", "cushion"))},
}


def garment_help():
    """``--garment``'s help: each garment's own words, the default marked."""
    option = DRAPE["garment"]
    return " or ".join(f"{c.value} ({c.help}{'; default' if c.value == option.default else ''})"
                       for c in option.choices)


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
        if isinstance(self.frames, bool) or not isinstance(self.frames, (int, np.integer)) or not (
                FRAME_RANGE[0] <= self.frames <= FRAME_RANGE[1]):
            raise ElliMannError(f"frames: must be an integer from {FRAME_RANGE[0]} to {FRAME_RANGE[1]}, "
                                f"got {self.frames!r}")
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
        if isinstance(self.max_vertices, bool) or not isinstance(self.max_vertices, (int, np.integer)) or \
                self.max_vertices < 100:
            raise ElliMannError(f"max_vertices: must be an integer of at least 100, got {self.max_vertices!r}")
        return self
