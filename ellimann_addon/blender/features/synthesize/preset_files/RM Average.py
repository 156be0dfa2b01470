import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 159.0
props.sh = 43.0
props.br = 117.0
props.wa = 104.0
props.hi = 117.0
props.reference_set = 'FEMALE'
