"""``blender --background --command ellimann …``: the command line (``ellimann_addon.cli.main``) registered
with Blender (``bpy.utils.register_cli_command``) when the add-on is."""

import bpy

from ..cli import PROG, main

_handle = None


def register():
    """Make ``blender --command ellimann …`` run :func:`ellimann_addon.cli.main`."""
    global _handle
    _handle = bpy.utils.register_cli_command(PROG, main)


def unregister():
    global _handle
    if _handle is not None:
        bpy.utils.unregister_cli_command(_handle)
        _handle = None
