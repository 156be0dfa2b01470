"""Clean (paper, Section 2.3.4): validate, fix frames, relabel axes, symmetrize, register to world."""

from . import operators, panel, validate

classes = operators.classes + validate.classes + panel.classes
