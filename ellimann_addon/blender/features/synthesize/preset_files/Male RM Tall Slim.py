import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 189.0
props.sh = 46.0
props.br = 90.0
props.wa = 74.0
props.hi = 90.0
props.reference_set = "MALE_FINE" if props.reference_set in ("FEMALE_FINE", "MALE_FINE") else "MALE"
