"""ElliMann: measurement-driven female mannequins built from convex ellipsoids and cushions.

``core`` is pure numpy (no Blender); ``blender`` is the thin bpy layer. Blender imports this
package only through ``register``/``unregister`` so that ``core`` stays importable anywhere.
"""

VERSION = "0.1.0"  # blender_manifest.toml's and pyproject.toml's (tests/core/test_packaging.py): ``ellimann --version``


def register():
    from . import blender

    blender.register()


def unregister():
    from . import blender

    blender.unregister()
