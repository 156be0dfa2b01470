"""Trace: a Base Mannequin over a reference mesh (new mannequin, add and fit ellipsoids, mirror them)."""

from . import mirror, operators, panel

classes = operators.classes + mirror.classes + panel.classes
