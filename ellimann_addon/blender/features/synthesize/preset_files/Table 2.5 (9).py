import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 165.25
props.sh = 41.5
props.br = 118.5
props.wa = 102.5
props.hi = 134.75
if props.reference_set == "MALE":  # a female body: from the male set back to the female one
    props.reference_set = "FEMALE"
