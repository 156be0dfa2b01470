"""Collision meshes of a mannequin's pieces: on the exact surfaces, shared sphere, bad levels refused."""

import numpy as np
import pytest

from devkit.toy import make_toy_mannequin
from ellimann_addon.core.drape.colliders import collision_pieces, triangle_count
from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.geometry.cushion import cushion_mesh


def test_ellipsoid_pieces_lie_on_their_ellipsoids():
    toy = make_toy_mannequin()
    pieces = collision_pieces(toy, sphere_subdivisions=1)
    assert [p.name for p in pieces] == list(toy.topology.names) and {p.kind for p in pieces} == {"ELLIPSOID"}
    assert triangle_count(pieces) == len(toy) * 80
    for i, piece in enumerate(pieces):
        local = (piece.world_vertices() - toy.center[i]) @ toy.rotation[i] / toy.semi_axes[i]
        assert np.allclose(np.linalg.norm(local, axis=1), 1.0)
    assert all(p.vertices is pieces[0].vertices for p in pieces)  # one sphere mesh for all


def test_cushions_replace_their_pair():
    toy = make_toy_mannequin()
    pairs = toy.topology.cushion_pairs
    pieces = collision_pieces(toy, cushions=True, sphere_subdivisions=2, cushion_subdivisions=2)
    cushions = [p for p in pieces if p.kind == "CUSHION"]
    assert len(cushions) == len(pairs) and len(pieces) == len(toy) - len(pairs)
    names = {p.name for p in pieces}
    for (i, j), piece in zip(pairs, cushions):
        assert toy.topology.names[i] not in names and toy.topology.names[j] not in names
        frames = [(toy.rotation[k], toy.center[k], toy.semi_axes[k]) for k in (i, j)]
        vertices, faces = cushion_mesh(*frames, subdivisions=2)
        assert np.allclose(piece.world_vertices(), vertices) and np.array_equal(piece.faces, faces)
        assert np.allclose(piece.matrix[:3, :3], toy.rotation[i])  # rigid: the first ellipsoid's frame


@pytest.mark.parametrize(
    "options",
    [
        {"sphere_subdivisions": 6},
        {"cushion_subdivisions": -1},
        {"sphere_subdivisions": 1.5},
        {"cushion_subdivisions": True},
    ],
)
def test_bad_levels_are_refused(options):
    name = next(iter(options))
    with pytest.raises(ElliMannError, match=f"{name}: must be an integer from 0 to 5"):
        collision_pieces(make_toy_mannequin(), cushions=True, **options)
