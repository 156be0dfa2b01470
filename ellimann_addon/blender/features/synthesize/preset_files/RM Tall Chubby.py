import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 171.0
props.sh = 53.0
props.br = 153.0
props.wa = 142.0
props.hi = 150.0
if props.reference_set == "MALE":  # a female body: from the male set back to the female one
    props.reference_set = "FEMALE"
