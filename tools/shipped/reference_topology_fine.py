"""ElliMann's fine topology: the shipped 40 parts (tools/shipped/reference_topology.py) and the pieces that fill where
they miss.

Where the 40 miss was measured on the Base Mannequin over its body: the body's volume outside every piece, each
missed cell given the region and skinning bone of its nearest vertex (refmodels/reference_female_regions.json).
Most of it lies in the bands the girth rules leave between the trunk's pieces (a girth part keeps clear of the
sections it does not follow: under the bust, below the waist), at the shoulders and armpits, round the thigh's top
(the groin, the inner thigh, the buttock's fold), at the back of the knee, the elbow, the heel and round the head.
Each new part is traced and fitted like the 40 (same selection language, same fit), keeps every rule (mirror twins,
girth flags, clear of the sections it does not depend on) and rides on one bone of the skeleton
(core.mannequin.skeleton.PART_BONES). Numbers go on from the 40's 15, head to feet; a cushion pair shares one.
"""

from dataclasses import replace

from .reference_topology import BUST, HEAD, HIPS, SHOULDERS, SPECS, WAIST, Select, Spec

# The chest's parts the shoulder section cuts (the 40's are never the widest there): they follow Sh, so exact mode
# narrows them with the shoulders (a wide upper chest on a big bust and narrow shoulders would otherwise set Sh), and
# Br, as the chest's parts do. No girth part follows two girths: one crossing two sections ties their factors
# together, and exact mode missed the waist of a big bust over a narrow waist.
SHOULDERS_AND_BUST = ("He", "Sh", "Br")

EXTRA_SPECS = (
    # the head's back and forehead, the jaw and the base of the neck: the head is no ellipsoid
    Spec(
        16,
        "a",
        "Occiput",
        "C",
        "head",
        True,
        HEAD,
        Select(regions=("head",), h=(0.90, 1.01), y=(-0.04, 1)),
        frame="fixed",
        cavities=True,
    ),
    Spec(
        16,
        "b",
        "Forehead",
        "C",
        "head",
        True,
        HEAD,
        Select(regions=("head",), h=(0.91, 1.01), y=(-1, -0.06)),
        inward=(0.0, 0.03, 0.0),
        frame="fixed",
        cavities=True,
    ),
    Spec(
        17,
        "a",
        "Jaw",
        "C",
        "head",
        True,
        HEAD,
        Select(regions=("head",), h=(0.85, 0.89), y=(-1, -0.06)),
        inward=(0.0, 0.03, 0.0),
        frame="fixed",
        cavities=True,
    ),
    Spec(
        18,
        "a",
        "Base of Neck",
        "C",
        "neck",
        True,
        SHOULDERS,  # its half-width follows Sh (5.6-13 cm on the female RMs): on He alone, a slim body took
        # a heavy one's of the same height
        Select(regions=("neck", "chest"), h=(0.83, 0.87), y=(-0.06, 0.04)),
        frame="fixed",
        clear=("Sh",),
    ),
    # the shoulders' front and back, the side of the chest under the arm, the bust's top and middle
    Spec(
        19,
        "a",
        "Upper Chest",
        "C",
        "chest",
        True,
        SHOULDERS_AND_BUST,
        Select(regions=("chest",), h=(0.77, 0.84), x=(0, 0.10), y=(-1, -0.02)),
        inward=(0.0, 0.05, 0.0),
        frame="fixed",
    ),
    Spec(
        20,
        "a",
        "Scapula",
        "L",
        "chest",
        True,
        SHOULDERS_AND_BUST,
        Select(regions=("chest",), h=(0.74, 0.83), x=(0.05, 0.15), y=(0.0, 1)),
        inward=(0.0, -0.04, 0.0),
        frame="fixed",
    ),
    Spec(
        21,
        "a",
        "Armpit",
        "L",
        "chest",
        True,
        SHOULDERS_AND_BUST,
        Select(regions=("chest",), h=(0.70, 0.79), x=(0.09, 1), y=(-0.09, 0.04)),
        frame="fixed",
    ),
    Spec(
        22,
        "a",
        "Upper Breast",
        "L",
        "chest",
        True,
        BUST,
        Select(regions=("chest",), h=(0.73, 0.78), x=(0.02, 0.14), y=(-1, -0.07)),
        inward=(0.0, 0.04, 0.0),
        frame="fixed",
    ),
    Spec(
        23,
        "a",
        "Sternum",
        "C",
        "chest",
        True,
        BUST,
        Select(regions=("chest",), h=(0.68, 0.77), x=(0, 0.04), y=(-1, -0.07)),
        inward=(0.0, 0.04, 0.0),
        frame="fixed",
    ),
    # under the bust: the rib cage's bottom, on the bust's side of the waist's clearance
    Spec(
        24,
        "a",
        "Lower Ribs",
        "C",
        "chest",
        True,
        BUST,
        Select(regions=("chest", "abdomen"), h=(0.665, 0.72)),
        frame="fixed",
    ),
    # between the waist and the hips: the belly's lower half, the small of the back, the flanks, the sacrum
    Spec(
        25,
        "a",
        "Lower Belly",
        "C",
        "abdomen",
        True,
        WAIST,
        Select(regions=("abdomen", "pelvis"), h=(0.53, 0.62), y=(-1, -0.03)),
        inward=(0.0, 0.05, 0.0),
        frame="fixed",
    ),
    Spec(
        25,
        "b",
        "Lumbar",
        "C",
        "abdomen",
        True,
        WAIST,
        Select(regions=("abdomen", "pelvis"), h=(0.53, 0.62), y=(-0.01, 1)),
        inward=(0.0, -0.05, 0.0),
        frame="fixed",
    ),
    Spec(
        26,
        "a",
        "Flank",
        "L",
        "abdomen",
        True,
        WAIST,
        Select(regions=("abdomen", "pelvis"), h=(0.53, 0.63), x=(0.07, 1)),
        frame="fixed",
    ),
    Spec(
        27,
        "a",
        "Sacrum",
        "C",
        "hips",
        True,
        HIPS,
        Select(bones=("spine05", "pelvis"), h=(0.45, 0.56), x=(0, 0.05), y=(-0.03, 1)),
        inward=(0.0, -0.04, 0.0),
        frame="fixed",
    ),
    # the arm's bend
    Spec(
        28,
        "a",
        "Elbow",
        "L",
        "arms",
        False,
        SHOULDERS,
        Select(bones=("upperarm02", "lowerarm01"), h=(0.60, 0.71)),
        frame="limb",
        margin=0.15,
    ),
    # the thigh's top and round it: the groin, the inner thigh, the outer and front thigh, the buttock's fold; the
    # back of the knee and the top of the shin
    Spec(
        29,
        "a",
        "Groin",
        "L",
        "legs",
        True,
        HIPS,
        Select(bones=("upperleg01", "pelvis"), h=(0.44, 0.52), x=(0.03, 0.15), y=(-1, -0.05)),
        inward=(0.0, 0.04, 0.0),
        frame="fixed",
    ),
    Spec(
        30,
        "a",
        "Inner Thigh",
        "L",
        "legs",
        True,
        HIPS,
        Select(bones=("upperleg01", "upperleg02"), h=(0.36, 0.48), x=(0.0, 0.09)),
        frame="limb",
        margin=0.15,
    ),
    Spec(
        31,
        "a",
        "Outer Thigh",
        "L",
        "legs",
        True,
        HIPS,
        Select(bones=("upperleg01", "upperleg02"), h=(0.34, 0.48), x=(0.12, 1)),
        frame="limb",
        margin=0.15,
    ),
    Spec(
        32,
        "a",
        "Front Thigh",
        "L",
        "legs",
        True,
        HIPS,
        Select(bones=("upperleg01", "upperleg02"), h=(0.32, 0.47), y=(-1, -0.07)),
        frame="limb",
        margin=0.15,
    ),
    Spec(
        33,
        "a",
        "Buttock Fold",
        "L",
        "legs",
        True,
        HIPS,
        Select(bones=("upperleg01", "upperleg02"), h=(0.36, 0.48), y=(-0.03, 1)),
        frame="limb",
        margin=0.15,
    ),
    Spec(
        34,
        "a",
        "Back of Knee",
        "L",
        "legs",
        True,
        HIPS,
        Select(bones=("upperleg02", "lowerleg01"), h=(0.24, 0.33), y=(-0.06, 1)),
        frame="limb",
        margin=0.15,
    ),
    Spec(
        35,
        "a",
        "Upper Shin",
        "L",
        "legs",
        True,
        HIPS,
        Select(bones=("lowerleg01",), h=(0.17, 0.28)),
        frame="limb",
        margin=0.15,
    ),
    # the breast's underside and the side of the hip above the hip section, the buttock's top
    Spec(
        37,
        "a",
        "Under Breast",
        "L",
        "chest",
        True,
        BUST,
        Select(regions=("chest",), h=(0.655, 0.715), x=(0.04, 0.17), y=(-1, -0.04)),
        inward=(0.0, 0.04, 0.0),
        frame="fixed",
    ),
    Spec(
        38,
        "a",
        "Outer Hip",
        "L",
        "hips",
        True,
        HIPS,
        Select(bones=("pelvis", "upperleg01"), h=(0.47, 0.58), x=(0.11, 1)),
        frame="fixed",
    ),
    Spec(
        39,
        "a",
        "Upper Gluteus",
        "L",
        "hips",
        True,
        HIPS,
        Select(bones=("pelvis", "spine05", "upperleg01"), h=(0.51, 0.61), x=(0.03, 1), y=(0.02, 1)),
        inward=(0.0, -0.05, 0.0),
        frame="fixed",
    ),
    # the chest's sides between the armpit and the waist, the shoulder's top, the knee's front
    Spec(
        40,
        "a",
        "Side Ribs",
        "L",
        "chest",
        True,
        BUST,
        Select(regions=("chest",), h=(0.66, 0.75), x=(0.08, 1), y=(-0.05, 0.08)),
        frame="fixed",
    ),
    Spec(
        41,
        "a",
        "Shoulder Top",
        "L",
        "shoulders",
        True,
        SHOULDERS,
        Select(bones=("clavicle", "shoulder01"), h=(0.80, 0.87), x=(0.06, 0.22)),
        inward=(0.0, 0.0, -0.03),
        frame="main",
    ),
    Spec(
        42,
        "a",
        "Kneecap",
        "L",
        "legs",
        True,
        HIPS,
        Select(bones=("upperleg02", "lowerleg01"), h=(0.25, 0.32), y=(-1, -0.01)),
        frame="limb",
        margin=0.15,
    ),
    # the foot round the 40's Foot ellipsoid
    Spec(36, "a", "Heel", "L", "feet", True, HIPS, Select(bones=("foot",), h=(0, 0.06), y=(-0.03, 1)), frame="fixed"),
    Spec(
        36, "b", "Instep", "L", "feet", True, HIPS, Select(bones=("foot",), h=(0, 0.07), y=(-0.13, -0.03)), frame="limb"
    ),
)

# How far a part may reach outside the body surface: 5 mm, as the 40's (mittens stay inside their hull), and what a
# part pays for the outside it covers: a cell outside the body costs what a cell inside that no other part fills is
# worth. Placed for the inside alone, the parts bulged out wherever the depth let them, and the last millimetre added
# about as much volume outside the body (excess) as it filled inside (5 mm gave 93.1 % coverage and 5.4 % excess on
# the Base Mannequin, 3 mm 90.8 % and 3.0 %); paying for the outside, 5 mm fills more than 4 mm did free on every RM
# but one (equal), with at most 3.6 % excess (docs/topology_fine_tried.md has the figures).
FINE_DEPTH = 0.005
FINE_OUTSIDE_COST = 1.0

# With more pieces there is less room to leave: each part keeps 0.0125 of the height clear of the sections it does not
# follow (the 40's keep 0.025) and, placed the second time, values volume another part covers too at 0.05 of the rest
# (the 40's: 0.25), so it spreads into what is still empty. The breast is not centred on the bust section: the upper
# breast, the under-breast and the sternum hold the section's outline, and a breast free to sit where the body's is
# fills more (docs/topology_fine_tried.md has what each change measured).
FINE_CLEARANCE = 0.0125
FINE_SHARED = 0.05
FREE_OF_LEVEL = ("Breast",)

# The parts keep clear of points 10 mm apart on the body's triangles, not only of its vertices: the heavy bodies'
# meshes are stretched (triangles up to 97 mm long on the chubby ones), and a thin part slipped out between the
# vertices (the Upper Gluteus reached 22.7 mm out of Tall Chubby's lumbar shelf, against the 4 mm then allowed).
FINE_WALL_SPACING = 0.01

FINE_SPECS = tuple(
    replace(
        spec,
        depth=spec.depth if spec.mitten else FINE_DEPTH,
        clearance=FINE_CLEARANCE,
        shared=FINE_SHARED,
        wall_spacing=None if spec.mitten else FINE_WALL_SPACING,
        outside_cost=None if spec.mitten else FINE_OUTSIDE_COST,
        level=None if spec.label in FREE_OF_LEVEL else spec.level,
    )
    for spec in SPECS + EXTRA_SPECS
)

# tools/shipped/coverage.py's chains on the fine topology: the 40's links, each with the new parts that join it.
FINE_CHAINS = {
    "leg": [
        ("Pelvis", "Gluteus", "Hip", "Outer Hip", "Upper Gluteus"),
        ("Thigh", "Inner Thigh", "Buttock Fold", "Outer Thigh", "Front Thigh", "Groin"),
        ("Knee", "Back of Knee", "Kneecap"),
        ("Calf", "Upper Shin"),
        ("Ankle",),
        ("Foot", "Heel", "Instep"),
        ("Toes",),
    ],
    "arm": [
        ("Deltoid", "Trapezius", "Shoulder Top"),
        ("Upper Arm",),
        ("Elbow",),
        ("Forearm",),
        ("Hand",),
        ("Fingers",),
    ],
    "neck, head": [
        ("Trapezius", "Upper Back", "Thorax", "Upper Chest", "Scapula"),
        ("Neck", "Base of Neck"),
        ("Cranium", "Face", "Jaw", "Occiput", "Forehead"),
    ],
    "trunk, front": [
        ("Thorax", "Breast", "Sternum", "Upper Breast", "Under Breast"),
        ("Lower Ribs",),
        ("Rectus Abdominalis",),
        ("Lower Belly",),
        ("Pelvis",),
    ],
    "trunk, back": [("Upper Back", "Scapula"), ("Lower Back",), ("Lumbar",), ("Pelvis", "Gluteus", "Sacrum")],
    "trunk, side": [
        ("Thorax", "Upper Back", "Armpit", "Side Ribs"),
        ("Lower Ribs",),
        ("Oblique",),
        ("Flank",),
        ("Hip",),
    ],
}
