"""The bpy layer: scene bridge, services, one package per feature, and the registry. Depends on core, never
the reverse. Imported lazily (``registry`` pulls in bpy), so ``services.teardown`` and friends load alone."""


def register():
    """Register ``registry.CLASSES`` in order, then run each of ``registry.HOOKS``."""
    import bpy

    from . import registry

    for cls in registry.CLASSES:
        bpy.utils.register_class(cls)
    for add, _ in registry.HOOKS:
        add()


def unregister():
    """The reverse of :func:`register`."""
    import bpy

    from . import registry

    for _, remove in reversed(registry.HOOKS):
        remove()
    for cls in reversed(registry.CLASSES):
        bpy.utils.unregister_class(cls)
