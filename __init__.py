"""Extension entry point: the add-on lives in ``ellimann_addon``; this file only forwards to it."""

from .ellimann_addon import register, unregister

__all__ = ["register", "unregister"]
