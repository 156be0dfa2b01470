"""tools/figures/overlap.py stands a mannequin where its body stands before core.geometry.volume.voxel_iou compares
them: on a ball whose answer is known in closed form."""

import numpy as np
import pytest

from ellimann_addon.core.geometry import volume
from ellimann_addon.core.geometry.mesh import icosphere
from ellimann_addon.core.geometry.mesh import volume as mesh_volume
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.topology import Part, Topology
from tools.figures.overlap import standing_in

RADIUS = 0.1
SPACING = 0.004


def ball(radius, center):
    topology = Topology([Part("1.a Ball", "C", "head", True, ("He",))])
    return Mannequin(topology, np.eye(3)[None], np.array([center], float), np.full((1, 3), radius))


def test_a_ball_standing_elsewhere_is_moved_onto_its_mesh_and_overlaps_it_by_the_volume_ratio():
    vertices, faces = icosphere(5)
    body = vertices * RADIUS + (0.0, 0.0, RADIUS)
    grid = volume.BodyVolume(body, faces).grid(SPACING, margin=volume.IOU_MARGIN)
    moved = standing_in(grid, ball(RADIUS, (0.4, -0.3, RADIUS)))  # beside the body, off its grid
    np.testing.assert_allclose(moved.center[0], (0.0, 0.0, RADIUS), atol=SPACING / 4)  # not moved up or down
    exact = mesh_volume(body, faces) / (4.0 / 3.0 * np.pi * RADIUS**3)  # the mesh is inscribed in the ball
    assert volume.voxel_iou(moved, grid=grid, cushions=False) == pytest.approx(exact, abs=0.01)
