"""The skin: Build Skin (a smooth closed skin over the active mannequin, bound to its armature), its panel, and the
preview skin that follows the Synthesize panel's Live updates."""

from . import live, operator, panel

classes = operator.classes + panel.classes


def register_hooks():
    live.register_hooks()


def unregister_hooks():
    live.unregister_hooks()
