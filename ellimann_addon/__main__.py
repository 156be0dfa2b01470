"""``python -m ellimann_addon …``: the ElliMann command line (the bpy module is needed for .blend/.glb/.obj)."""

from .blender import teardown
from .blender.cli import main

teardown.exit_with(main())
