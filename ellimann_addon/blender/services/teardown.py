"""Leaving a Python process that imported Blender as the ``bpy`` module.

Blender 4.2-4.5 as a module crash (SIGSEGV) or hang in their own teardown at interpreter exit once any
property with a Python callback (``update=``, ``poll=``) has been registered, unregistered or not:
the work is done and the files are written, but the exit code is 139. 5.0 and later exit cleanly.
On those versions the process leaves through :func:`exit_without_teardown` instead: scripts end
with ``teardown.exit_with(code)`` where they would ``sys.exit(code)``.
"""

import os
import shutil
import sys


def needs_workaround():
    bpy = sys.modules.get("bpy")
    # Inside a Blender executable (``blender --command``) Blender owns the exit; binary_path is empty in
    # the module.
    return bpy is not None and not bpy.app.binary_path and bpy.app.version < (5, 0, 0)


def exit_without_teardown(code):
    """Flush, remove Blender's session temporary folder (its teardown would have), then ``os._exit``."""
    import bpy

    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    tempdir = bpy.app.tempdir
    if tempdir and os.path.basename(os.path.normpath(tempdir)).startswith("blender_"):
        shutil.rmtree(tempdir, ignore_errors=True)
    os._exit(code)


def exit_with(code):
    """``sys.exit(code)``, skipping Blender's teardown where it crashes."""
    if needs_workaround():
        exit_without_teardown(code)
    sys.exit(code)
