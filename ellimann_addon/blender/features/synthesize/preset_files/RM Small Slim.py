import bpy

props = bpy.context.scene.ellimann_synthesis

props.he = 148.0
props.sh = 31.0
props.br = 85.0
props.wa = 63.0
props.hi = 83.0
props.reference_set = 'FEMALE'
