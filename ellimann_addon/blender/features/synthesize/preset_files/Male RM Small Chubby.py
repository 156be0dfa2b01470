import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 162.0
props.sh = 55.0
props.br = 122.0
props.wa = 116.0
props.hi = 114.0
props.reference_set = "MALE_FINE" if props.reference_set in ("FEMALE_FINE", "MALE_FINE") else "MALE"
