"""Every operator, panel and menu id of the add-on, in one place (tests check the prefixes).

Operators are ``ellimann.verb_noun`` with classes ``ELLIMANN_OT_verb_noun``; panels and menus are
``ELLIMANN_PT_...`` / ``ELLIMANN_MT_...``.
"""

NEW_MANNEQUIN = "ellimann.new_mannequin"
ADD_ELLIPSOID = "ellimann.add_ellipsoid"
FIT_ELLIPSOID = "ellimann.fit_ellipsoid"
MIRROR_ELLIPSOIDS = "ellimann.mirror_ellipsoids"
MIRROR_SIDE = "ellimann.mirror_side"
RELABEL_AXES = "ellimann.relabel_axes"
SYMMETRIZE_CENTRAL = "ellimann.symmetrize_central"
REGISTER_MANNEQUIN = "ellimann.register_mannequin"
BUILD_CUSHIONS = "ellimann.build_cushions"
MEASURE_MANNEQUIN = "ellimann.measure_mannequin"
MEASURE_BODY = "ellimann.measure_body"
SYNTHESIZE_FROM_MESH = "ellimann.synthesize_from_mesh"
VALIDATE_MANNEQUIN = "ellimann.validate_mannequin"
FIX_FRAMES = "ellimann.fix_frames"
SYNTHESIZE_MANNEQUIN = "ellimann.synthesize_mannequin"
ADD_MEASUREMENT_PRESET = "ellimann.add_measurement_preset"
APPLY_MEASUREMENT_PRESET = "ellimann.apply_measurement_preset"
OPEN_MEASUREMENT_FILE = "ellimann.open_measurement_file"
DRAPE_GARMENT = "ellimann.drape_garment"
EXPORT_MANNEQUIN = "ellimann.export_mannequin"
BUILD_REFERENCE_SET = "ellimann.build_reference_set"
ADD_REFERENCE_BODIES = "ellimann.add_reference_bodies"
REMOVE_REFERENCE_BODY = "ellimann.remove_reference_body"
ADD_ARMATURE = "ellimann.add_armature"
APPLY_POSE = "ellimann.apply_pose"
REST_POSE = "ellimann.rest_pose"
IMPORT_BVH = "ellimann.import_bvh"
BUILD_SKIN = "ellimann.build_skin"

PANEL_MAIN = "ELLIMANN_PT_main"
PANEL_TRACE = "ELLIMANN_PT_trace"
PANEL_PART = "ELLIMANN_PT_part"
PANEL_CLEAN = "ELLIMANN_PT_clean"
PANEL_CUSHIONS = "ELLIMANN_PT_cushions"
PANEL_MEASURE = "ELLIMANN_PT_measure"
PANEL_SYNTHESIZE = "ELLIMANN_PT_synthesize"
PANEL_DRAPE = "ELLIMANN_PT_drape"
PANEL_POSE = "ELLIMANN_PT_pose"
PANEL_REFERENCES = "ELLIMANN_PT_references"
PANEL_SKIN = "ELLIMANN_PT_skin"

# Sub-panels of PANEL_MAIN sort by bl_order. Room is left after Measure for the Synthesize (60),
# Pose (65) and Drape (70) panels that other parts of the add-on add.
# Building a reference set (55) comes before synthesizing from it.
PANEL_ORDER = {
    PANEL_TRACE: 10,
    PANEL_PART: 20,
    PANEL_CLEAN: 30,
    PANEL_CUSHIONS: 40,
    PANEL_SKIN: 45,
    PANEL_MEASURE: 50,
    PANEL_REFERENCES: 55,
}
SYNTHESIZE_ORDER = 60
POSE_ORDER = 65
DRAPE_ORDER = 70

MENU_OBJECT = "ELLIMANN_MT_object"
MENU_MEASUREMENT_PRESETS = "ELLIMANN_MT_measurement_presets"


def class_name(idname):
    """'ellimann.add_ellipsoid' -> 'ELLIMANN_OT_add_ellipsoid' (what Blender calls the operator type)."""
    module, _, name = idname.partition(".")
    return f"{module.upper()}_OT_{name}"
