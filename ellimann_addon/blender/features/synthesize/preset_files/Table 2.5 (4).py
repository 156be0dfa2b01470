import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 153.75
props.sh = 47.25
props.br = 118.5
props.wa = 122.25
props.hi = 134.75
if props.reference_set in ("MALE", "MALE_FINE"):  # a female body: from a male set to the female one of its topology
    props.reference_set = "FEMALE_FINE" if props.reference_set == "MALE_FINE" else "FEMALE"
