"""The one registry of the add-on: every class Blender registers, in order, and the hooks that add what
is not a class (pointer properties, handlers, menu entries, the CLI command).

``blender.register()`` registers :data:`CLASSES` in order, then runs each hook's ``register``;
``unregister()`` does the reverse. The tests walk the same tuples (tests/blender/test_register.py,
test_ids.py, test_panels.py). A new feature adds its package to :data:`FEATURES` (a ``classes``
tuple, optionally ``register_hooks`` / ``unregister_hooks`` and ``MENU_ENTRIES``); the sidebar shows
sub-panels by ``bl_order`` (``ids``), whatever the order here.
"""

import bpy

from . import cli_command
from .bridge import props
from .features import (
    clean,
    cushions,
    drape,
    export,
    main_panel,
    measure,
    menus,
    part,
    pose,
    references,
    skin,
    synthesize,
    trace,
)

# One package per user task, in the sidebar's order.
FEATURES = (trace, part, clean, cushions, skin, measure, references, synthesize, pose, drape, export)

# Property groups first (pointers need them), the main panel before its sub-panels.
CLASSES = props.classes + main_panel.classes + tuple(c for feature in FEATURES for c in feature.classes) + menus.classes

# (menu, draw function) appended to Blender's menus.
MENU_ENTRIES = menus.MENU_ENTRIES + tuple(e for feature in FEATURES for e in getattr(feature, "MENU_ENTRIES", ()))


def operators():
    """Every operator class, in registration order."""
    return [cls for cls in CLASSES if issubclass(cls, bpy.types.Operator)]


def panels():
    """Every panel class: the main panel, then the sub-panels in registration order."""
    return [cls for cls in CLASSES if issubclass(cls, bpy.types.Panel)]


def property_groups():
    return [cls for cls in CLASSES if issubclass(cls, bpy.types.PropertyGroup)]


def _add_menu_entries():
    for menu, draw in MENU_ENTRIES:
        getattr(bpy.types, menu).append(draw)


def _remove_menu_entries():
    for menu, draw in reversed(MENU_ENTRIES):
        getattr(bpy.types, menu).remove(draw)


# (register, unregister) pairs, run after the classes are registered (and in reverse before they go).
HOOKS = (
    (props.register_hooks, props.unregister_hooks),
    *((f.register_hooks, f.unregister_hooks) for f in FEATURES if hasattr(f, "register_hooks")),
    (_add_menu_entries, _remove_menu_entries),
    (cli_command.register, cli_command.unregister),
)
