"""Compatibility only: ``DrapeSettings`` stays importable from here until it moves to ``core/options.py``.
The cloth engine is ``services/drape.py``; the Drape feature is ``features/drape/``."""

from .services.drape import DrapeSettings

__all__ = ["DrapeSettings"]
