"""Synthesize: five measurements (and any of the extra ones) in, a mannequin out; presets, a measurement file
opened as one, Live updates of the last one, and Synthesize from Mesh (a body mesh's twin)."""

from . import from_mesh, live, measurement_file, operators, panel, presets, props

# Registered in this order (the property group before the pointer to it), unregistered in reverse.
classes = (
    props.classes + operators.classes + from_mesh.classes + presets.classes + measurement_file.classes + panel.classes
)


def register_hooks():
    props.register_hooks()
    live.register_hooks()


def unregister_hooks():
    live.unregister_hooks()
    props.unregister_hooks()
