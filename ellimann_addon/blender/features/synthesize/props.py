"""The Synthesize feature's scene settings, ``Scene.ellimann_synthesis``: the request (five fields in cm)
and the options; every change of a field makes a live update when Live is on (:mod:`.live`)."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, PointerProperty, StringProperty

from ....core.constants import ABSURD_LIMITS, MEASUREMENT_LABELS, RANGES, REFERENCE_MEASUREMENTS
from ....core.synthesis import DEFAULT_NORMALIZE, DEFAULT_POWER, POWER_LIMITS
from .live import on_request_change


def _measurement(key):
    low, high = ABSURD_LIMITS[key]
    soft_low, soft_high = RANGES[key]
    return FloatProperty(
        name=key, default=REFERENCE_MEASUREMENTS["average"][key], min=low, max=high, soft_min=soft_low,
        soft_max=soft_high, step=25, precision=2, update=on_request_change,
        description=f"{MEASUREMENT_LABELS[key]} in cm. Reference range {soft_low:g}-{soft_high:g} cm (outside it "
                    f"the result is extrapolated); accepted {low:g}-{high:g} cm")


class ELLIMANN_PG_synthesis(bpy.types.PropertyGroup):
    """The synthesis request and options of a scene."""

    he: _measurement("He")
    sh: _measurement("Sh")
    br: _measurement("Br")
    wa: _measurement("Wa")
    hi: _measurement("Hi")
    mode: EnumProperty(
        name="Mode", default="EXACT", update=on_request_change,
        description="How the mannequin is made from the Reference Mannequins: IDW alone misses the request by up "
                    "to a few %; Exact refines it until m_T matches",
        items=(("EXACT", "Exact", "IDW, then a gentle refinement until m_T matches the request to 0.001% "
                                  "(beyond the paper)"),
               ("IDW", "IDW", "Segmented inverse-distance weighting alone, as in the paper (m_T off by up to a few "
                              "%)")))
    output: EnumProperty(
        name="Pieces", default="ELLIPSOIDS",
        description="What Synthesize builds: ellipsoids only, or cushions (convex hulls of each cushion pair) in "
                    "place of their two ellipsoids, which are kept but hidden",
        items=(("ELLIPSOIDS", "Ellipsoids", "One ellipsoid object per part"),
               ("CUSHIONS", "Cushions", "Cushions (convex hulls) for the cushion pairs, ellipsoids for the rest; "
                                        "slower to build")))
    normalize: EnumProperty(
        name="Interpolate", default=DEFAULT_NORMALIZE.upper(), update=on_request_change,
        description="What IDW averages over the Reference Mannequins: their proportions (ElliMann's default, "
                    "closer to the request) or their geometry as it is (the paper's Eq. 2.1)",
        items=(("PROPORTIONAL", "Proportions", "Average each part in proportion to its RM's measurements: heights "
                "to He, widths to the part's own measurement, then scale to the request"),
               ("HEIGHT", "Height Proportions", "Average heights in proportion to each RM's He, widths as they are"),
               ("NONE", "Geometry (Paper)", "Average the RMs' geometry as it is, as in the paper (Eq. 2.1)")))
    metric: EnumProperty(
        name="Distance", default="RAW", update=on_request_change,
        description="How IDW measures the distance from the request to each Reference Mannequin's measurements "
                    "(nearer ones weigh more)",
        items=(("RAW", "cm", "IDW distances in cm, as in the paper: the wide-ranging girths weigh more than He "
                             "and Sh"),
               ("NORMALIZED", "Normalized", "Each measurement divided by its reference range L, so all five "
                                            "weigh alike")))
    power: FloatProperty(name="p", default=DEFAULT_POWER, min=POWER_LIMITS[0], max=POWER_LIMITS[1],
                         update=on_request_change, description="IDW power (the paper uses 2)")
    live: BoolProperty(name="Live", default=False, update=on_request_change,
                       description="Update the last synthesized mannequin in place while the fields change")
    target: PointerProperty(name="Last Synthesized", type=bpy.types.Collection,
                            poll=lambda _self, collection: collection.ellimann.is_mannequin,
                            description="The mannequin that Live updates")
    references: StringProperty(name="References", subtype="DIR_PATH", default="",
                               description="Folder with the five Reference Mannequin .json files "
                                           "(empty: the shipped reference_blends/)")
    status: StringProperty(name="Status", description="Outcome of the last live update")
    live_ms: FloatProperty(name="Live Update Time", description="Duration of the last live update (ms)")


classes = (ELLIMANN_PG_synthesis,)


def register_hooks():
    bpy.types.Scene.ellimann_synthesis = PointerProperty(type=ELLIMANN_PG_synthesis)


def unregister_hooks():
    del bpy.types.Scene.ellimann_synthesis
