"""Project-wide constants: the version, section heights, the paper's tables (the measurements: ``core.measurements``).

Measurements are in centimetres (what tailors type); geometry is in metres (Blender's unit).
"""

from .measurements import MEASUREMENTS

VERSION = "0.1.0"  # blender_manifest.toml's and pyproject.toml's (tests/core/test_packaging.py): ``ellimann --version``

# Section heights as fractions of He above the lowest point of the feet (the paper's Section 2.3.5; the
# sections and the parts they cut: docs/topology.md); the tools in ../shared/refmodels use the same numbers.
# These are the female reference set's; another set carries its own in its manifest (core.synthesis.reference_set).
SECTION_FRACTIONS = {"Sh": 0.790, "Br": 0.720, "Wa": 0.645, "Hi": 0.500}
FEMALE_SET = "female"  # the name of the shipped default reference set, whose landmarks are the constants here
GIRTHS = ("Br", "Wa", "Hi")

CM_PER_M = 100.0

# Table 2.3 of the paper: the five Reference Mannequins (cm).
REFERENCE_MEASUREMENTS = {
    "small_slim": {"He": 148.0, "Sh": 31.0, "Br": 85.0, "Wa": 63.0, "Hi": 83.0},
    "tall_slim": {"He": 171.0, "Sh": 30.0, "Br": 84.0, "Wa": 63.0, "Hi": 84.0},
    "small_chubby": {"He": 148.0, "Sh": 45.0, "Br": 147.0, "Wa": 142.0, "Hi": 152.0},
    "tall_chubby": {"He": 171.0, "Sh": 53.0, "Br": 153.0, "Wa": 142.0, "Hi": 150.0},
    "average": {"He": 159.0, "Sh": 43.0, "Br": 117.0, "Wa": 104.0, "Hi": 117.0},
}

# L: the min-max of each row of Table 2.3.
RANGES = {
    key: (
        min(me[key] for me in REFERENCE_MEASUREMENTS.values()),
        max(me[key] for me in REFERENCE_MEASUREMENTS.values()),
    )
    for key in MEASUREMENTS
}

# Plausibility limits of a piece (m), the geometry's counterpart of ABSURD_LIMITS: a mannequin with a
# piece outside them is refused (JSON files, Blender collections, synthesis results), naming the part,
# the field and the range. No body (He at most 2.5 m) has a semi-axis beyond half its height; 10 um is
# far below any piece of a body and far above where float32 (Blender's matrices) loses a scale. Centres
# may be anywhere a scene puts a mannequin beside others (a line-up of dozens spans tens of metres);
# at 100 m Blender's float32 locations still resolve 8 um.
SEMI_AXIS_LIMITS = (1e-5, 3.0)
CENTER_LIMIT = 100.0  # largest |x|, |y| or |z| of a piece's centre


def quartile_points(key, ranges=None):
    """The three inner quartile points of L (``ranges``, default RANGES) for one measurement (the paper's 243
    grid)."""
    low, high = (ranges or RANGES)[key]
    return tuple(low + (high - low) * q for q in (0.25, 0.5, 0.75))


# Table 2.5: the ten mannequins of Figures 2.18 and 2.19 (cm).
TABLE_2_5 = (
    (153.75, 35.75, 101.25, 102.5, 134.75),
    (153.75, 35.75, 118.5, 102.5, 117.5),
    (153.75, 41.5, 135.75, 102.5, 117.5),
    (153.75, 47.25, 118.5, 122.25, 134.75),
    (159.5, 41.5, 118.5, 82.75, 117.5),
    (159.5, 47.25, 101.25, 82.75, 117.5),
    (165.25, 35.75, 101.25, 82.75, 117.5),
    (165.25, 41.5, 101.25, 122.25, 117.5),
    (165.25, 41.5, 118.5, 102.5, 134.75),
    (165.25, 47.25, 135.75, 122.25, 117.5),
)

# Table 2.4: the paper's relative errors (%) over the 243 grid, for comparison.
PAPER_TABLE_2_4 = {
    "mean": {"He": 0.2, "Sh": 2.6, "Br": 2.4, "Wa": 0.8, "Hi": 0.9},
    "max": {"He": 0.4, "Sh": 6.6, "Br": 7.0, "Wa": 1.5, "Hi": 2.2},
    "min": {"He": 0.0, "Sh": 0.1, "Br": 0.0, "Wa": 0.0, "Hi": 0.1},
}

# Icosphere levels (core.geometry.mesh.icosphere: 10 * 4^n + 2 vertices, 20 * 4^n triangles), one name per use.
UNIT_SPHERE_LEVEL = 3  # the unit-sphere mesh every ellipsoid object shares (642 vertices)
CUSHION_LEVEL = 4  # cushion hulls by default (Build Cushions, Synthesize): 2,562 vertices, capsule volume within 0.5%
CUSHION_LEVELS = (1, 6)  # cushion hulls one may ask for (Build Cushions, MJCF): 42 to 40,962 vertices
LIVE_CUSHION_LEVEL = 3  # cushions rebuilt during Synthesize's live updates (642 vertices: about half a second)
MJCF_CUSHION_LEVEL = 3  # cushion meshes in an MJCF file by default
COLLIDER_LEVELS = (0, 5)  # cloth colliders: 20 to 20,480 triangles per piece (the solver's cost grows 4x a level)
DISTANCE_CUSHION_LEVEL = 3  # cushion hulls of garment_fit.BodyPieces by default
FIT_CUSHION_LEVEL = 4  # cushion hulls a drape's fit statistics are measured against (finer than the colliders)
CLEARING_CUSHION_LEVEL = 3  # cushion hulls a new garment is moved clear of (inscribed in the level-4 ones)
