import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 162.0
props.sh = 44.0
props.br = 88.0
props.wa = 72.0
props.hi = 88.0
props.reference_set = "MALE_FINE" if props.reference_set in ("FEMALE_FINE", "MALE_FINE") else "MALE"
