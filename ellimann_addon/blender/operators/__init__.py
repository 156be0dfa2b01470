"""ElliMann's operators, one module per operator family; all ids live in ``..ids``."""

import importlib

# Registered in this order, unregistered in reverse.
_MODULES = ("trace", "mirror", "clean", "cushions", "measure", "validate", "drape", "export")


def _modules():
    return [importlib.import_module(f".{name}", __package__) for name in _MODULES]


def classes():
    """Every operator class, for tests and menus."""
    return [cls for module in _modules() for cls in module.classes]


def register():
    for module in _modules():
        module.register()


def unregister():
    for module in reversed(_modules()):
        module.unregister()
