"""``python -m ellimann_addon …``: the ElliMann command line (the bpy module is needed for .blend/.glb/.obj)."""

from .blender.cli import main
from .blender.services import teardown

teardown.exit_with(main())
