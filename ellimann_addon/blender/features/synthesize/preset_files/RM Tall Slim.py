import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 171.0
props.sh = 30.0
props.br = 84.0
props.wa = 63.0
props.hi = 84.0
if props.reference_set in ("MALE", "MALE_FINE"):  # a female body: from a male set to the female one of its topology
    props.reference_set = "FEMALE_FINE" if props.reference_set == "MALE_FINE" else "FEMALE"
