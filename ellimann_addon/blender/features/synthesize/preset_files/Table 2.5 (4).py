import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 153.75
props.sh = 47.25
props.br = 118.5
props.wa = 122.25
props.hi = 134.75
if props.reference_set == "MALE":  # a female body: from the male set back to the female one
    props.reference_set = "FEMALE"
