"""Measure: m_T (He, Sh, Br, Wa, Hi in cm) of the active mannequin, optionally its section curves."""

from . import operator, panel

classes = operator.classes + panel.classes
