import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 159.5
props.sh = 41.5
props.br = 118.5
props.wa = 82.75
props.hi = 117.5
if props.reference_set in ("MALE", "MALE_FINE"):  # a female body: from a male set to the female one of its topology
    props.reference_set = "FEMALE_FINE" if props.reference_set == "MALE_FINE" else "FEMALE"
