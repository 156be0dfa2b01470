"""Pose: an armature for the active mannequin, the standard poses, the walk cycle, BVH motion onto it."""

from . import bvh, operators, panel, props

classes = props.classes + operators.classes + bvh.classes + panel.classes
register_hooks, unregister_hooks = props.register_hooks, props.unregister_hooks
