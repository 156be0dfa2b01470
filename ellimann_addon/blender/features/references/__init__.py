"""Build Reference Set: Reference Mannequins from a traced Base Mannequin and N >= 3 bodies, saved as a
reference-set folder (core/fitting/reference_build.py, core/synthesis/manifest.py)."""

from . import operators, panel, props

classes = props.classes + operators.classes + panel.classes
register_hooks, unregister_hooks = props.register_hooks, props.unregister_hooks
