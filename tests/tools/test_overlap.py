"""The voxel IoU of tools/overlap.py, on a sphere whose answer is known in closed form."""

import numpy as np
import pytest

from ellimann_addon.core.mannequin import Mannequin, Part, Topology
from ellimann_addon.core.mesh import icosphere
from ellimann_addon.core.mesh import volume as mesh_volume
from tools.overlap import voxel_iou

RADIUS = 0.1
SPACING = 0.004


def ball(radius, center):
    topology = Topology([Part("1.a Ball", "C", "head", True, ("He",))])
    return Mannequin(topology, np.eye(3)[None], np.array([center], float), np.full((1, 3), radius))


def test_a_ball_overlaps_its_own_mesh_wherever_it_stands_and_a_smaller_one_by_the_volume_ratio():
    vertices, faces = icosphere(5)
    body = vertices * RADIUS + (0.0, 0.0, RADIUS)
    mesh = mesh_volume(body, faces)
    # standing on the floor beside the body: moved onto the body's vertical line, not up or down
    iou, covered, excess = voxel_iou(ball(RADIUS, (0.3, -0.2, RADIUS)), body, faces, SPACING)
    exact = mesh / (4.0 / 3.0 * np.pi * RADIUS**3)  # the mesh is inscribed in the ball
    assert iou == pytest.approx(exact, abs=0.01) and covered == pytest.approx(1.0, abs=0.01)
    assert excess == pytest.approx(1.0 - exact, abs=0.01)
    small = 0.8 * RADIUS  # a smaller ball on the same floor: inside the body, so IoU = its share of the body
    iou, covered, excess = voxel_iou(ball(small, (0.0, 0.0, small)), body, faces, SPACING)
    assert iou == pytest.approx(4.0 / 3.0 * np.pi * small**3 / mesh, abs=0.02) and excess < 0.01
