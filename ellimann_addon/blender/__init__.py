"""The bpy layer: properties, operators, panels and the CLI command. Depends on core, never the reverse."""

import importlib

# Registered in this order, unregistered in reverse.
_MODULES = ("props", "operators", "panels", "menus", "synthesize", "synthesize_panel", "drape_panel", "cli_command")


def _modules():
    return [importlib.import_module(f".{name}", __package__) for name in _MODULES]


def register():
    for module in _modules():
        module.register()


def unregister():
    for module in reversed(_modules()):
        module.unregister()
