"""Drape: a garment sized from the active mannequin, on its convex pieces, with Blender cloth."""

from . import operator, panel, props

classes = props.classes + operator.classes + panel.classes
register_hooks, unregister_hooks = props.register_hooks, props.unregister_hooks
