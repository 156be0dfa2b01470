"""Part: the active object's ElliMann fields (its edits are Blender's own property edits)."""

from . import panel

classes = panel.classes
