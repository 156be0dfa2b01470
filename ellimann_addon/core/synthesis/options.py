"""Synthesis options: :class:`SynthesisOptions` (mode, metric, power, normalize, name; keyword-only), what
``synthesize`` / ``synthesize_batch`` take, and ``SYNTHESIS``, the one table of their defaults, labels,
descriptions and choices (the command line's and ``Scene.ellimann_synthesis``'s)."""

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import ElliMannError
from ..option_table import Choice, Option

SYNTHESIS = {
    "mode": Option(
        "Mode",
        "exact",
        "How the mannequin is made from the Reference Mannequins: IDW alone misses the request by up to a few %; "
        "Exact refines it until m_T matches",
        "exact (default): refine until m_T matches the request; idw: the paper's interpolation alone",
        choices=(
            Choice(
                "idw", "IDW", "Segmented inverse-distance weighting alone, as in the paper (m_T off by up to a few %)"
            ),
            Choice(
                "exact",
                "Exact",
                "IDW, then a gentle refinement until m_T matches the request to 0.001% (beyond the paper)",
            ),
        ),
        shown=("exact", "idw"),
    ),
    "metric": Option(
        "Distance",
        "raw",
        "How IDW measures the distance from the request to each Reference Mannequin's measurements (nearer ones "
        "weigh more)",
        "IDW distance: raw cm as in the paper (default) or normalized by the ranges L",
        choices=(
            Choice(
                "raw", "cm", "IDW distances in cm, as in the paper: the wide-ranging girths weigh more than He and Sh"
            ),
            Choice(
                "normalized", "Normalized", "Each measurement divided by its reference range L, so all five weigh alike"
            ),
        ),
    ),
    "power": Option("p", 2.0, "IDW power (the paper uses 2)", "IDW power p (default {default:g})", limits=(0.5, 16.0)),
    "normalize": Option(
        "Interpolate",
        "proportional",
        "What IDW averages over the Reference Mannequins: their proportions (ElliMann's default, closer to the "
        "request) or their geometry as it is (the paper's Eq. 2.1)",
        "what IDW averages: proportional (default): each part's heights in proportion to He and widths to its own "
        "measurement; height: heights only; none: the RMs' geometry as it is (the paper)",
        choices=(
            Choice("none", "Geometry (Paper)", "Average the RMs' geometry as it is, as in the paper (Eq. 2.1)"),
            Choice("height", "Height Proportions", "Average heights in proportion to each RM's He, widths as they are"),
            Choice(
                "proportional",
                "Proportions",
                "Average each part in proportion to its RM's measurements: "
                "heights to He, widths to the part's own measurement, then "
                "scale to the request",
            ),
        ),
        shown=("proportional", "height", "none"),
    ),
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


def is_number(value):
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def check_options(mode=DEFAULT_MODE, metric=DEFAULT_METRIC, power=DEFAULT_POWER, normalize=DEFAULT_NORMALIZE):
    if mode not in MODES:
        raise ElliMannError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    if normalize not in NORMALIZATIONS:
        raise ElliMannError(f"normalize must be one of {', '.join(NORMALIZATIONS)}, got {normalize!r}")
    if metric not in METRICS:
        raise ElliMannError(f"metric must be one of {', '.join(METRICS)}, got {metric!r}")
    if not is_number(power) or not POWER_LIMITS[0] <= power <= POWER_LIMITS[1]:
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
