import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 171.0
props.sh = 53.0
props.br = 153.0
props.wa = 142.0
props.hi = 150.0
if props.reference_set in ("MALE", "MALE_FINE"):  # a female body: from a male set to the female one of its topology
    props.reference_set = "FEMALE_FINE" if props.reference_set == "MALE_FINE" else "FEMALE"
