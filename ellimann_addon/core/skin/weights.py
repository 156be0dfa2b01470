"""Which pieces each skin vertex follows: weights that blend smoothly where neighbours meet.

A vertex belongs to its nearest piece (its *owner*) and, where the owner's neighbours in the body (the pairs that
blend, ``core.skin.field.blend_pairs``) come near, to them too: a neighbour i weighs (1 - t)^2 with
t = (d_i - d_nearest) / w, w that pair's blend width, so the weights change over the same band in which the
surface blends, and never reach a piece that does not touch the owner (an arm beside the torso). The four
largest weights are kept, normalised.

Live, each vertex follows its pieces' affine motion from one mannequin to the next (:func:`follow_pieces`: the
slider's preview, no new surface). Posed, the skin follows the bones by linear-blend skinning with weights made
from the joints (``core.skin.skinning``), which the piece weights only place in the skeleton: pieces do not end at
joints. :func:`follow_pieces` applies those too (glTF and Blender's Armature modifier apply them alike).
"""

import numpy as np

from .field import piece_distance

INFLUENCES = 4  # pieces (and bones) per vertex: what glTF's JOINTS_0 / WEIGHTS_0 hold


def piece_weights(vertices, owner, rotation, center, semi_axes, pairs, widths):
    """(pieces (V, 4) int, weights (V, 4)): each vertex's owner and the neighbours that reach it, by weight
    (unused slots: the owner with weight 0)."""
    count = len(center)
    neighbours = [[] for _ in range(count)]
    for (i, j), width in zip(pairs, widths):
        neighbours[i].append((j, width))
        neighbours[j].append((i, width))
    order = np.argsort(owner, kind="stable")
    starts = np.searchsorted(owner[order], np.arange(count + 1))
    most = 1 + max((len(n) for n in neighbours), default=0)
    candidates = np.repeat(owner[:, None], most, axis=1)
    scores = np.zeros((len(vertices), most))
    scores[:, 0] = 1.0
    for piece in range(count):
        rows = order[starts[piece] : starts[piece + 1]]
        if len(rows) == 0:
            continue
        points = vertices[rows]
        own = piece_distance(points, rotation[piece], center[piece], semi_axes[piece])
        for slot, (other, width) in enumerate(neighbours[piece], start=1):
            beyond = piece_distance(points, rotation[other], center[other], semi_axes[other]) - own
            candidates[rows, slot] = other
            scores[rows, slot] = np.clip(1.0 - beyond / width, 0.0, 1.0) ** 2
    keep = np.argsort(-scores, axis=1, kind="stable")[:, :INFLUENCES]
    pieces = np.take_along_axis(candidates, keep, axis=1)
    weights = np.take_along_axis(scores, keep, axis=1)
    return pieces, weights / weights.sum(axis=1, keepdims=True)


def piece_motions(rest, moved):
    """(n, 3, 4): each piece's affine map from ``rest`` to ``moved`` (two mannequins of one topology): x ->
    c' + R' diag(D' / D) R^T (x - c)."""
    linear = (moved.rotation * (moved.semi_axes / rest.semi_axes)[:, None, :]) @ np.swapaxes(rest.rotation, 1, 2)
    offset = moved.center - np.einsum("nij,nj->ni", linear, rest.center)
    return np.concatenate([linear, offset[:, :, None]], axis=2)


def follow_pieces(vertices, pieces, weights, motions):
    """Skin vertices (V, 3) moved by their pieces' (or bones') affine ``motions`` (n, 3, 4), blended by
    ``weights`` (V, 4) of ``pieces`` (V, 4)."""
    blended = np.einsum("vk,vkij->vij", weights, motions[pieces])
    return np.einsum("vij,vj->vi", blended[:, :, :3], vertices) + blended[:, :, 3]
