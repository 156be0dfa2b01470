"""Cushions: the convex hull of every cushion pair as a closed mesh object."""

from . import operator, panel

classes = operator.classes + panel.classes
