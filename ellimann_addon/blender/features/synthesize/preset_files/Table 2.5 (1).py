import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 153.75
props.sh = 35.75
props.br = 101.25
props.wa = 102.5
props.hi = 134.75
if props.reference_set == "MALE":  # a female body: from the male set back to the female one
    props.reference_set = "FEMALE"
