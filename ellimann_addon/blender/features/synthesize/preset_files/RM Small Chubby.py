import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 148.0
props.sh = 45.0
props.br = 147.0
props.wa = 142.0
props.hi = 152.0
if props.reference_set == "MALE":  # a female body: from the male set back to the female one
    props.reference_set = "FEMALE"
