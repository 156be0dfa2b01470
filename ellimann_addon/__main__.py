"""``python -m ellimann_addon …``: the ElliMann command line (numpy only; Blender's bpy for .blend/.glb/.obj)."""

from .cli import main_exit

main_exit()
