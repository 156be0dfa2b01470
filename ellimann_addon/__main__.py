"""``python -m ellimann_addon …``: the ElliMann command line (the bpy module is needed for .blend/.glb/.obj)."""

import sys

from .blender.cli import main

sys.exit(main())
