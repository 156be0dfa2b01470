import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 165.25
props.sh = 47.25
props.br = 135.75
props.wa = 122.25
props.hi = 117.5
if props.reference_set == "MALE":  # a female body: from the male set back to the female one
    props.reference_set = "FEMALE"
