import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 159.5
props.sh = 41.5
props.br = 118.5
props.wa = 82.75
props.hi = 117.5
if props.reference_set == "MALE":  # a female body: from the male set back to the female one
    props.reference_set = "FEMALE"
