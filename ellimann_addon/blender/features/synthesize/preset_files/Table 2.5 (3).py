import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 153.75
props.sh = 41.5
props.br = 135.75
props.wa = 102.5
props.hi = 117.5
if props.reference_set == "MALE":  # a female body: from the male set back to the female one
    props.reference_set = "FEMALE"
