import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 176.0
props.sh = 51.0
props.br = 104.0
props.wa = 92.0
props.hi = 101.0
props.reference_set = "MALE_FINE" if props.reference_set in ("FEMALE_FINE", "MALE_FINE") else "MALE"
