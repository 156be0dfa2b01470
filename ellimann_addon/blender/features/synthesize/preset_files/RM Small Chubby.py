import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 148.0
props.sh = 45.0
props.br = 147.0
props.wa = 142.0
props.hi = 152.0
if props.reference_set in ("MALE", "MALE_FINE"):  # a female body: from a male set to the female one of its topology
    props.reference_set = "FEMALE_FINE" if props.reference_set == "MALE_FINE" else "FEMALE"
