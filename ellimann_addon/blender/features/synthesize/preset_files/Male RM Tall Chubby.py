import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 189.0
props.sh = 58.0
props.br = 128.0
props.wa = 120.0
props.hi = 118.0
props.reference_set = "MALE_FINE" if props.reference_set in ("FEMALE_FINE", "MALE_FINE") else "MALE"
