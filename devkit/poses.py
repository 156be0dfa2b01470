"""The toy mannequin re-posed for garment work: arms hung from the shoulders in an A-pose.

devkit.toy's arms lean the other way (hands at the hips, upper ends far out), which leaves a
garment no room between arm and torso. The reference bodies (../shared/refmodels) stand in an
A-pose with the upper arms 35 degrees from vertical; this variant does the same.
"""

import numpy as np

from devkit.toy import make_toy_mannequin, rotation_from_vector
from ellimann_addon.core.geometry.frames import mirror_frame

A_POSE_DEGREES = 35.0
SHOULDER_JOINT = (0.19, 0.02, 1.31)  # upper end of the left arm's long axis (m)


def make_apose_toy():
    """The toy with each arm's long axis from SHOULDER_JOINT down and out at A_POSE_DEGREES."""
    m = make_toy_mannequin()
    angle = np.radians(A_POSE_DEGREES)
    down = np.array([np.sin(angle), 0.0, -np.cos(angle)])
    left, right = m.topology.index["5.a Arm.L"], m.topology.index["5.a Arm.R"]
    m.rotation[left] = rotation_from_vector((0.0, -angle, 0.0))  # local z: up and in
    m.center[left] = np.asarray(SHOULDER_JOINT) + m.semi_axes[left, 2] * down
    m.rotation[right], m.center[right] = mirror_frame(m.rotation[left], m.center[left])
    m.semi_axes[right] = m.semi_axes[left]
    m.name = "toy (A-pose)"
    return m.check()
