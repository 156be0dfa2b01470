"""Pictures for the docs drawn through Blender (README.md)."""
