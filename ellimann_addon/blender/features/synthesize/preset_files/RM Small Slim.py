import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 148.0
props.sh = 31.0
props.br = 85.0
props.wa = 63.0
props.hi = 83.0
if props.reference_set == "MALE":  # a female body: from the male set back to the female one
    props.reference_set = "FEMALE"
