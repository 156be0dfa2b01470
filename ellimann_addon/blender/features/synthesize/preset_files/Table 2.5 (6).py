import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 159.5
props.sh = 47.25
props.br = 101.25
props.wa = 82.75
props.hi = 117.5
if props.reference_set == "MALE":  # a female body: from the male set back to the female one
    props.reference_set = "FEMALE"
