"""Measure: m_T (He, Sh, Br, Wa, Hi in cm) and the extra measurements of the active mannequin, optionally its
section curves; Measure Body Mesh for a scan or another tool's body."""

from . import body, operator, panel

classes = operator.classes + body.classes + panel.classes
