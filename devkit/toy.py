"""A small synthetic mannequin with every kind of part (central, paired, cushions), and rotations."""

import numpy as np

from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.topology import Part, Topology


def rotation_from_vector(v):
    """Rotation matrix from a rotation vector (Rodrigues), numpy only."""
    v = np.asarray(v, dtype=float)
    angle = np.linalg.norm(v)
    if angle < 1e-15:
        return np.eye(3)
    k = v / angle
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


TOY_PARTS = [
    Part("1.a Head", "C", "head", False, ("He",)),
    Part("2.a Chest", "C", "torso", True, ("He", "Br"), "2.b Belly"),
    Part("2.b Belly", "C", "torso", True, ("He", "Wa"), "2.a Chest"),
    Part("3.a Pelvis", "C", "hips", True, ("He", "Hi")),
    Part("4.a Trapezius.L", "L", "shoulders", True, ("He", "Sh")),
    Part("4.a Trapezius.R", "R", "shoulders", True, ("He", "Sh")),
    Part("5.a Arm.L", "L", "arms", False, ("He", "Sh")),
    Part("5.a Arm.R", "R", "arms", False, ("He", "Sh")),
    Part("6.a Thigh.L", "L", "legs", True, ("He", "Hi"), "6.b Shin.L"),
    Part("6.b Shin.L", "L", "legs", True, ("He", "Hi"), "6.a Thigh.L"),
    Part("6.a Thigh.R", "R", "legs", True, ("He", "Hi"), "6.b Shin.R"),
    Part("6.b Shin.R", "R", "legs", True, ("He", "Hi"), "6.a Thigh.R"),
]

# centre (m), rotation vector, semi-axes (m) of the left and central parts; right = mirror.
TOY_GEOMETRY = {
    "1.a Head": ((0.0, 0.0, 1.50), (0.1, 0.0, 0.0), (0.08, 0.10, 0.12)),
    "2.a Chest": ((0.0, 0.0, 1.18), (0.05, 0.0, 0.0), (0.16, 0.11, 0.16)),
    "2.b Belly": ((0.0, -0.01, 1.00), (0.0, 0.0, 0.0), (0.14, 0.10, 0.12)),
    "3.a Pelvis": ((0.0, 0.01, 0.85), (-0.1, 0.0, 0.0), (0.17, 0.12, 0.12)),
    "4.a Trapezius.L": ((0.13, 0.01, 1.30), (0.0, 0.3, 0.1), (0.09, 0.06, 0.05)),
    "5.a Arm.L": ((0.30, 0.02, 1.05), (0.0, 0.5, 0.0), (0.05, 0.05, 0.28)),
    "6.a Thigh.L": ((0.09, 0.0, 0.62), (0.0, 0.08, 0.0), (0.08, 0.08, 0.22)),
    "6.b Shin.L": ((0.10, 0.01, 0.25), (0.05, 0.02, 0.0), (0.05, 0.05, 0.24)),
}


def make_toy_mannequin():
    topology = Topology(TOY_PARTS)
    n = len(topology)
    rotation, center, semi = np.zeros((n, 3, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    flip = np.diag([-1.0, 1.0, 1.0])
    for i, part in enumerate(topology):
        source = part.name if part.side != "R" else part.name[:-2] + ".L"
        c, rv, d = TOY_GEOMETRY[source]
        r = rotation_from_vector(rv)
        if part.side == "R":
            r = flip @ r @ flip  # mirror as a rotation: reflected axes with x flipped back
            c = (-c[0], c[1], c[2])
        rotation[i], center[i], semi[i] = r, c, d
    return Mannequin(topology, rotation, center, semi, name="toy", role="reference")
