import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 159.0
props.sh = 43.0
props.br = 117.0
props.wa = 104.0
props.hi = 117.0
if props.reference_set == "MALE":  # a female body: from the male set back to the female one
    props.reference_set = "FEMALE"
