"""``python -m ellimann_addon …``: the ElliMann command line (the bpy module is needed for .blend/.glb/.obj)."""

import sys

from .blender.cli import main

code = main()
from .blender import teardown  # noqa: E402  (after main: it looks at whether main imported bpy)

if teardown.needs_workaround():
    teardown.exit_without_teardown(code)
sys.exit(code)
