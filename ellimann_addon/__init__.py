"""ElliMann: measurement-driven female mannequins built from convex ellipsoids and cushions.

``core`` is pure numpy (no Blender); ``blender`` is the thin bpy layer. Blender imports this
package only through ``register``/``unregister`` so that ``core`` stays importable anywhere.
"""

from .core.constants import VERSION  # noqa: F401  (the package's version: ``ellimann_addon.VERSION``)


def register():
    from . import blender

    blender.register()


def unregister():
    from . import blender

    blender.unregister()
