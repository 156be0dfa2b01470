"""The names the measurement files use, and which of ElliMann's eleven each one is, by definition.

ElliMann's measurements (docs/measurements.md; constants.py and measure/extra.py): He the stature; Sh the body's
width across the deltoids (the x extent of the level section at 0.79 He on the female set, 0.80 on the male);
Br, Wa, Hi the girths (a tape's convex hull) of the level sections at 0.72, 0.645 and 0.50 He (female; male
0.72, 0.625, 0.515), the bust, the natural waist and the seat; neck the smallest girth square to the neck below the
jaw; upper_arm the arm's girth across its axis a quarter of the way from the shoulder point to the fingertip;
thigh one leg 0.02 He below the crotch; calf the largest girth of the lower leg; crotch_height the crotch above the
soles; arm_length the shoulder point (the outermost point of the Sh section) to the fingertip, straight.

A file's name maps onto one of them only where the file's definition measures the same thing at the same place;
a similar name is not enough (each mapping says why). Two survey measurements are used only to predict a missing
one (``PREDICTORS``): the neck's girth at its base and the breadth between the acromia (the shoulder tips), which
the shipped survey holds beside the five. Every mapping is one ``Mapping`` row; docs/formats/measurement_files.md
is generated from these tables (``mapping_markdown``; tests/core/sizing/test_mapping_doc.py checks the page).
"""

from dataclasses import dataclass

from ..measurements import EXTRA_MEASUREMENTS, MEASUREMENTS

KEYS = MEASUREMENTS + EXTRA_MEASUREMENTS  # ElliMann's eleven
PREDICTORS = ("neck_base", "biacromial")  # survey columns a file may give that only help predict a missing one


@dataclass(frozen=True)
class Mapping:
    """One name of a file format: ``key`` is the ElliMann measurement it is (one of ``KEYS``), a survey column
    that only helps predict (``PREDICTORS``), or None (recognised, not used); ``why`` says so by definition."""

    name: str
    key: str | None
    why: str


def _table(rows):
    return {row.name: row for row in rows}


# Seamly2D / Valentina: the known-measurement table (measurements_def.cpp, A01-Q03), names as the files hold them.
SEAMLY_KNOWN = tuple(
    """
height height_neck_back height_scapula height_armpit height_waist_side height_hip height_gluteal_fold
height_knee height_calf height_ankle_high height_ankle height_highhip height_waist_front height_bustpoint
height_shoulder_tip height_neck_front height_neck_side height_neck_back_to_knee height_waist_side_to_knee
height_waist_side_to_hip height_knee_to_ankle height_neck_back_to_waist_side height_waist_back width_shoulder
width_bust width_waist width_hip width_abdomen_to_hip indent_neck_back indent_waist_back indent_ankle_high
hand_palm_length hand_length hand_palm_width hand_palm_circ hand_circ foot_width foot_length foot_circ
foot_instep_circ head_circ head_length head_depth head_width head_crown_to_neck_back head_chin_to_neck_back
neck_mid_circ neck_circ highbust_circ bust_circ lowbust_circ rib_circ waist_circ highhip_circ hip_circ
neck_arc_f highbust_arc_f bust_arc_f size lowbust_arc_f rib_arc_f waist_arc_f highhip_arc_f hip_arc_f
neck_arc_half_f highbust_arc_half_f bust_arc_half_f lowbust_arc_half_f rib_arc_half_f waist_arc_half_f
highhip_arc_half_f hip_arc_half_f neck_arc_b highbust_arc_b bust_arc_b lowbust_arc_b rib_arc_b waist_arc_b
highhip_arc_b hip_arc_b neck_arc_half_b highbust_arc_half_b bust_arc_half_b lowbust_arc_half_b rib_arc_half_b
waist_arc_half_b highhip_arc_half_b hip_arc_half_b hip_with_abdomen_arc_f body_armfold_circ body_bust_circ
body_torso_circ hip_circ_with_abdomen neck_front_to_waist_f neck_front_to_waist_flat_f armpit_to_waist_side
shoulder_tip_to_waist_side_f neck_side_to_waist_f neck_side_to_waist_bustpoint_f neck_front_to_highbust_f
highbust_to_waist_f neck_front_to_bust_f bust_to_waist_f lowbust_to_waist_f rib_to_waist_side
shoulder_tip_to_armfold_f neck_side_to_bust_f neck_side_to_highbust_f shoulder_center_to_highbust_f
shoulder_tip_to_waist_side_b neck_side_to_waist_b neck_back_to_waist_b neck_side_to_waist_scapula_b
neck_back_to_highbust_b highbust_to_waist_b neck_back_to_bust_b bust_to_waist_b lowbust_to_waist_b
shoulder_tip_to_armfold_b neck_side_to_bust_b neck_side_to_highbust_b shoulder_center_to_highbust_b
waist_to_highhip_f waist_to_hip_f waist_to_highhip_side waist_to_highhip_b waist_to_hip_b waist_to_hip_side
shoulder_slope_neck_side_angle shoulder_slope_neck_side_length shoulder_slope_neck_back_angle
shoulder_slope_neck_back_height shoulder_slope_shoulder_tip_angle neck_back_to_across_back
across_back_to_waist_b shoulder_length shoulder_tip_to_shoulder_tip_f across_chest_f armfold_to_armfold_f
shoulder_tip_to_shoulder_tip_half_f across_chest_half_f shoulder_tip_to_shoulder_tip_b across_back_b
armfold_to_armfold_b shoulder_tip_to_shoulder_tip_half_b across_back_half_b neck_front_to_shoulder_tip_f
neck_back_to_shoulder_tip_b neck_width bustpoint_to_bustpoint bustpoint_to_neck_side bustpoint_to_lowbust
bustpoint_to_waist bustpoint_to_bustpoint_half bustpoint_neck_side_to_waist bustpoint_to_shoulder_tip
bustpoint_to_waist_front bustpoint_to_bustpoint_halter bustpoint_to_shoulder_center bustpoint_to_neck_front
shoulder_tip_to_waist_front neck_front_to_waist_side neck_side_to_waist_side_f shoulder_tip_to_waist_back
shoulder_tip_to_waist_b_1in_offset neck_back_to_waist_side neck_side_to_waist_side_b neck_side_to_armfold_f
neck_side_to_armpit_f neck_side_to_bust_side_f neck_side_to_armfold_b neck_side_to_armpit_b
neck_side_to_bust_side_b arm_shoulder_tip_to_wrist_bent arm_shoulder_tip_to_elbow_bent arm_elbow_to_wrist_bent
arm_elbow_circ_bent arm_shoulder_tip_to_wrist arm_shoulder_tip_to_elbow arm_elbow_to_wrist arm_armpit_to_wrist
arm_armpit_to_elbow arm_elbow_to_wrist_inside arm_upper_circ arm_above_elbow_circ arm_elbow_circ arm_lower_circ
arm_wrist_circ arm_shoulder_tip_to_armfold_line arm_neck_side_to_wrist arm_neck_side_to_finger_tip armscye_circ
armscye_length armscye_width arm_neck_side_to_outer_elbow leg_crotch_to_floor leg_waist_side_to_floor
leg_thigh_upper_circ leg_thigh_mid_circ leg_knee_circ leg_knee_small_circ leg_calf_circ leg_ankle_high_circ
leg_ankle_circ leg_knee_circ_bent leg_ankle_diag_circ leg_crotch_to_ankle leg_waist_side_to_ankle
leg_waist_side_to_knee crotch_length crotch_length_b crotch_length_f rise_length_side_sitting rise_length_diag
rise_length_b rise_length_f rise_length_side neck_back_to_waist_front waist_to_waist_halter waist_natural_circ
waist_natural_arc_f waist_natural_arc_b waist_to_natural_waist_f waist_to_natural_waist_b
arm_neck_back_to_elbow_bent arm_neck_back_to_wrist_bent arm_neck_side_to_elbow_bent arm_neck_side_to_wrist_bent
arm_across_back_center_to_elbow_bent arm_across_back_center_to_wrist_bent arm_armscye_back_center_to_wrist_bent
neck_back_to_bust_front neck_back_to_armfold_front neck_back_to_armfold_front_to_waist_side
highbust_back_over_shoulder_to_armfold_front highbust_back_over_shoulder_to_waist_front
neck_back_to_armfold_front_to_neck_back across_back_center_to_armfold_front_to_across_back_center
neck_back_to_armfold_front_to_highbust_back armfold_to_armfold_bust armfold_to_bust_front
highbust_b_over_shoulder_to_highbust_f armscye_arc dart_width_shoulder dart_width_bust dart_width_waist
""".split()
)
SEAMLY_CUSTOM = "@"  # a custom measurement's name begins with it
ELLIMANN_CUSTOM = "@ellimann_"  # what ElliMann writes for the measurements the known table has no name for

_SH_NOT = (
    "over the body's surface between the shoulder tips (the acromia), not the straight width across the deltoids "
    "at 0.79 He that Sh is"
)
SEAMLY = _table(
    (
        Mapping("height", "He", "vertical distance from the crown of the head to the floor: the stature"),
        Mapping(
            "bust_circ",
            "Br",
            "around the bust, parallel to the floor: the level girth at the bust points, where Br's section at "
            "0.72 He lies",
        ),
        Mapping(
            "waist_circ", "Wa", "around the natural waist: the narrowest part of the trunk, where Wa's section lies"
        ),
        Mapping(
            "hip_circ",
            "Hi",
            "around the hips where the buttocks protrude most, parallel to the floor: Hi's section at 0.50 He",
        ),
        Mapping(
            "neck_mid_circ",
            "neck",
            "around the neck about halfway between jaw and torso: the neck's smallest girth below the jaw, as "
            "ElliMann's neck (and the survey's, taken below the larynx)",
        ),
        Mapping("leg_thigh_upper_circ", "thigh", "the fullest part of the upper thigh near the crotch"),
        Mapping("leg_calf_circ", "calf", "the largest girth of the lower leg"),
        Mapping(
            "leg_crotch_to_floor",
            "crotch_height",
            "from the crotch (touching the body) down to the floor: the inside leg",
        ),
        Mapping(
            "width_shoulder",
            "biacromial",
            "straight across from shoulder tip to shoulder tip (the acromia): the survey's biacromial breadth, "
            "8.5 cm less than Sh on the survey's women (36.5 vs 45.0 cm); used only to predict Sh",
        ),
        Mapping(
            "neck_circ",
            "neck_base",
            "around the base of the neck (neck back, sides and front): the survey's neck base girth, 4 cm more "
            "than its neck (37.1 vs 33.0 cm); used only to predict",
        ),
        Mapping("shoulder_tip_to_shoulder_tip_f", None, _SH_NOT + " (across the front)"),
        Mapping("shoulder_tip_to_shoulder_tip_b", None, _SH_NOT + " (across the back)"),
        Mapping("shoulder_length", None, "from the neck side to the shoulder tip: one shoulder's slope, not a width"),
        Mapping("across_back_b", None, "between the armscyes across the back, below and inside the deltoids"),
        Mapping("width_bust", None, "a breadth (side to side), not a girth"),
        Mapping("highbust_circ", None, "high under the arms, above Br's level"),
        Mapping("lowbust_circ", None, "under the breasts, below Br's level"),
        Mapping("waist_natural_circ", None, "at the obliques' indentation or below the navel, not the narrowest waist"),
        Mapping("highhip_circ", None, "where the abdomen protrudes most, above Hi's level"),
        Mapping("hip_circ_with_abdomen", None, "two arcs added over the abdomen, not a level girth"),
        Mapping("leg_thigh_mid_circ", None, "halfway between crotch and knee, well below thigh's level"),
        Mapping(
            "arm_upper_circ",
            None,
            "at the armpit's level, above upper_arm's section (a quarter of the way down the arm, near its middle)",
        ),
        Mapping(
            "arm_shoulder_tip_to_wrist",
            None,
            "along the arm from the acromion to the wrist; arm_length runs straight from the deltoid's outermost "
            "point to the fingertip",
        ),
        Mapping(
            "arm_neck_side_to_finger_tip",
            None,
            "from the neck's side over the shoulder and down the arm, not from the shoulder point",
        ),
        Mapping("size", None, "the front bust arc (a synonym of bust_arc_f), not a girth"),
    )
)
SEAMLY_OTHER = "every other name of the known table: no ElliMann measurement is taken there"

# FreeSewing: config/measurements.mjs (values in mm; shoulderSlope in degrees). It has no stature.
FREESEWING_KNOWN = tuple(
    """
    ankle biceps bustFront bustPointToUnderbust bustSpan chest crossSeam crossSeamFront crotchDepth heel head highBust
    highBustFront hips hpsToBust hpsToWaistBack hpsToWaistFront inseam knee neck seat seatBack shoulderSlope
    shoulderToElbow shoulderToShoulder shoulderToWrist underbust upperLeg waist waistBack waistToArmpit waistToFloor
    waistToHips waistToKnee waistToSeat waistToUnderbust waistToUpperLeg wrist
    """.split()
)
FREESEWING_DEGREES = ("shoulderSlope",)
FREESEWING = _table(
    (
        Mapping("chest", "Br", "around the fullest part of the chest, kept horizontal: the level girth at the bust"),
        Mapping("waist", "Wa", "around the narrowest part of the waist below the ribcage, horizontal"),
        Mapping("seat", "Hi", "around the fullest part of the buttocks, horizontal: Hi's section at 0.50 He"),
        Mapping(
            "neck",
            "neck",
            "where a shirt collar sits (below the larynx, as the survey's neck: FreeSewing's base values, 340 and "
            "380 mm, are the survey's neck, not its neck base)",
        ),
        Mapping(
            "biceps",
            "upper_arm",
            "around the fullest part of the upper arm, near its middle, where upper_arm's section lies (a quarter "
            "of the way from the shoulder point to the fingertip)",
        ),
        Mapping(
            "upperLeg", "thigh", "around the leg a bit below the crotch, horizontal: thigh's section 0.02 He below it"
        ),
        Mapping("inseam", "crotch_height", "vertically from the crotch down to the floor"),
        Mapping("hips", None, "at the top of the hip bones, well above Hi's level (the seat is Hi)"),
        Mapping("highBust", None, "above the bust, under the arms"),
        Mapping("underbust", None, "under the breasts, below Br's level"),
        Mapping("shoulderToShoulder", None, "over the back from one shoulder tip to the other, not a straight width"),
        Mapping(
            "shoulderToWrist",
            None,
            "from the shoulder tip along a slightly bent arm to the wrist; arm_length reaches the fingertip",
        ),
        Mapping("waistToFloor", None, "the waist's height, not the stature"),
    )
)
FREESEWING_OTHER = "every other FreeSewing measurement: no ElliMann measurement is taken there"
FREESEWING_ELLIMANN = "ellimann"  # the set's own section for what FreeSewing has no name for (He, Sh, ...)

# Size charts (CSV): ElliMann's own keys, and the words charts use for the same measurements (ASTM D5585-style
# tables, a brand's grading). Headers are matched without regard to case or surrounding spaces.
CHART = _table(
    tuple(Mapping(key, key, "ElliMann's own key") for key in KEYS)
    + (
        Mapping("height", "He", "the stature"),
        Mapping("stature", "He", "the stature"),
        Mapping("bust", "Br", "the level girth at the fullest part of the bust"),
        Mapping("chest", "Br", "the level girth at the fullest part of the chest"),
        Mapping("waist", "Wa", "the natural waist's girth"),
        Mapping("hip", "Hi", "the girth at the fullest part of the buttocks"),
        Mapping("hips", "Hi", "a chart's hips are its full hip, at the fullest part of the buttocks"),
        Mapping("seat", "Hi", "the girth at the fullest part of the buttocks"),
        Mapping("full hip", "Hi", "the girth at the fullest part of the buttocks"),
        Mapping("neck", "neck", "a chart's neck is its collar girth, below the larynx"),
        Mapping("neck base", "neck_base", "the girth at the base of the neck; used only to predict"),
        Mapping("biceps", "upper_arm", "the fullest part of the upper arm, near its middle"),
        Mapping("thigh", "thigh", "the upper thigh's girth just below the crotch"),
        Mapping("calf", "calf", "the largest girth of the lower leg"),
        Mapping("inseam", "crotch_height", "crotch to floor"),
        Mapping("inside leg", "crotch_height", "crotch to floor"),
        Mapping("crotch height", "crotch_height", "crotch to floor"),
        Mapping("biacromial", "biacromial", "straight between the shoulder tips; used only to predict Sh"),
        Mapping(
            "shoulder", None, "a chart's shoulder runs over the back between the shoulder tips, not across the deltoids"
        ),
        Mapping("shoulder width", None, "over the back between the shoulder tips, not the width across the deltoids"),
        Mapping("high hip", None, "above Hi's level"),
        Mapping("high bust", None, "above Br's level"),
        Mapping("underbust", None, "below Br's level"),
        Mapping("arm length", None, "a chart's arm length ends at the wrist; write ElliMann's as arm_length"),
        Mapping("sleeve length", None, "shoulder tip to wrist along the arm"),
        Mapping("weight", None, "not a measurement of the shape"),
    )
)
CHART_LABELS = ("size", "label", "name")  # the column naming each row
FORMATS = {"vit": SEAMLY, "vst": SEAMLY, "freesewing": FREESEWING, "chart": CHART}


_CHART_FOLDED = {name.casefold(): row for name, row in CHART.items()}


def chart_mapping(header):
    """The Mapping of a chart's column header (no unit suffix; case and runs of spaces ignored), or None when it
    is not a name ElliMann knows."""
    return _CHART_FOLDED.get(" ".join(header.split()).casefold())


def seamly_mapping(name):
    """(Mapping or None, known): a Seamly2D/Valentina name's mapping (ElliMann's own custom ones included) and
    whether the format knows it (the known table, or any custom ``@`` name)."""
    if name in SEAMLY:
        return SEAMLY[name], True
    if name.startswith(ELLIMANN_CUSTOM) and name[len(ELLIMANN_CUSTOM) :] in KEYS:
        key = name[len(ELLIMANN_CUSTOM) :]
        return Mapping(name, key, "ElliMann's own measurement, written by ElliMann as a custom one"), True
    return None, name in SEAMLY_KNOWN or name.startswith(SEAMLY_CUSTOM)


def freesewing_mapping(name):
    """(Mapping or None, known) of a FreeSewing measurement name."""
    if name in FREESEWING:
        return FREESEWING[name], True
    return None, name in FREESEWING_KNOWN or name in FREESEWING_DEGREES
