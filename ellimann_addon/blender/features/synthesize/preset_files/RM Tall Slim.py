import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 171.0
props.sh = 30.0
props.br = 84.0
props.wa = 63.0
props.hi = 84.0
if props.reference_set == "MALE":  # a female body: from the male set back to the female one
    props.reference_set = "FEMALE"
