"""The skin's bone weights before ``core.skin.skinning`` (for bench_skin_posing's before/after): the pieces' weights
summed per bone (each vertex follows its nearest piece and the neighbours that reach it, so a vertex follows the
bones of the pieces it lies on, wherever the joints are)."""

import numpy as np

from ellimann_addon.core.mannequin.skeleton import JOINT_COUNT, part_bones
from ellimann_addon.core.skin.weights import INFLUENCES


def bone_weights_before(skin):
    """(bones (V, 4), weights (V, 4)) of a core Skin as they were made before: its piece weights summed per bone."""
    bone = part_bones(skin.mannequin.topology)[skin.pieces]
    dense = np.zeros((len(skin.pieces), JOINT_COUNT))
    np.add.at(dense, (np.arange(len(skin.pieces))[:, None], bone), skin.weights)
    keep = np.argsort(-dense, axis=1, kind="stable")[:, :INFLUENCES]
    kept = np.take_along_axis(dense, keep, axis=1)
    return np.where(kept > 0.0, keep, 0), kept / kept.sum(axis=1, keepdims=True)
