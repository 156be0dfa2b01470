"""Segmented IDW (paper, Eq. 2.1) and proportional IDW: the weights of the Reference Mannequins for each part
and the interpolated geometry (see ``core.synthesis.synthesize`` for the method)."""

import numpy as np

from ..constants import RANGES
from ..errors import MannequinError, Problem
from ..geometry.frames import SAGITTAL_REFLECTION, rotation_mean, symmetrize_central
from ..mannequin.joints import JOINT_SIDES, anchor_indices, mirror_joints
from ..mannequin.skeleton import JOINT_ANCHORS, JOINT_COUNT, JOINT_NAMES
from ..measurements import MEASUREMENTS
from .options import DEFAULT_NORMALIZE, DEFAULT_POWER

ZERO_DISTANCE = 1e-9  # closer than this (cm, or range units) is the RM's own point


def _metric_scale(metric, ranges=RANGES):
    """Per measurement, what one unit of IDW distance is: 1 cm ("raw") or the width of the set's range L."""
    if metric == "raw":
        return np.ones(len(MEASUREMENTS))
    # at least 1 cm: a set whose bodies share a measurement has a range of width 0 there
    return np.array([max(ranges[key][1] - ranges[key][0], 1.0) for key in MEASUREMENTS])


def _inverse_distance(distance, power):
    """IDW weights along the last axis; a zero distance takes all the weight (shared if several)."""
    zero = distance <= ZERO_DISTANCE
    nearest = np.where(zero, np.inf, distance).min(axis=-1, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        # (d_min / d)^p <= 1: no overflow for tiny distances or large p.
        relative = np.where(zero, 0.0, (nearest / np.where(zero, 1.0, distance)) ** power)
    weights = np.where(zero.any(axis=-1, keepdims=True), zero.astype(float), relative)
    return weights / weights.sum(axis=-1, keepdims=True)


def idw_weights(reference, requests, metric="raw", power=DEFAULT_POWER):
    """Weights (B, s, k) of the k RMs for each interpolated part s (left and central) of each request.

    Non-negative, summing to 1 over k. See the module docstring for parts whose sub-space
    does not separate some RMs.
    """
    requests = np.atleast_2d(np.asarray(requests, dtype=float))
    scale = _metric_scale(metric, reference.ranges)
    diff = (requests[:, None, :] - reference.measurements[None]) / scale  # (B, k, 5)
    sub = np.sqrt(np.einsum("bkm,sm->bsk", diff * diff, reference._mask))
    full = np.sqrt(np.sum(diff * diff, axis=-1))
    w_sub = _inverse_distance(sub, power)  # (B, s, k)
    w_full = _inverse_distance(full, power)  # (B, k)
    coincide = reference._coincide.astype(float)  # (s, k, k)
    group_full = np.einsum("sjl,bl->bsj", coincide, w_full)
    group_size = coincide.sum(axis=-1)  # (s, k)
    share = np.divide(group_size * w_full[:, None, :], group_full, out=np.ones_like(group_full), where=group_full > 0.0)
    weights = w_sub * share
    return weights / weights.sum(axis=-1, keepdims=True)


def center_scale(horizontal, vertical):
    """(..., 3) scale of a centre: x and y (about the registration origin) by the width, z (about the floor)
    by the height."""
    return np.stack([horizontal, horizontal, vertical], axis=-1)


def normalized_points(points, roots, along, horizontal, vertical):
    """Points (k, m, 3) divided by their scales (k, m): (k, m, 3, 3), the anchor, lengthwise and crosswise parts
    (axis -2), such that ``scaled_points`` of them at the same scales gives the points back. A limb's point
    (``along`` (m, 3): its limb's unit direction) is anchored at its limb's root (``roots`` (k, m, 3)), which
    scales as any centre; its offset from the root scales by the vertical scale along the limb and by the
    horizontal across it, so that a limb keeps its direction however heights and widths scale. Any other point
    (``along`` 0, ``roots`` the point itself) is its own anchor, its offsets 0."""
    offset = points - roots
    lengthwise = np.einsum("kmi,mi->km", offset, along)[..., None] * along
    return np.stack(
        [
            roots / center_scale(horizontal, vertical),
            lengthwise / vertical[..., None],
            (offset - lengthwise) / horizontal[..., None],
        ],
        axis=-2,
    )


def scaled_points(parts, horizontal, vertical):
    """The points (..., m, 3) of ``normalized_points``' parts (..., m, 3, 3) at scales (..., m)."""
    return (
        parts[..., 0, :] * center_scale(horizontal, vertical)
        + parts[..., 1, :] * vertical[..., None]
        + parts[..., 2, :] * horizontal[..., None]
    )


def axis_scale(rotation, horizontal, vertical, along=None):
    """(..., 3) scale of each semi-axis: vertical^v * horizontal^(1 - v), v = the axis' share along world z, or
    along its limb's direction where ``along`` (..., 3) is not zero (a limb's pieces lengthen as its bones do).

    The rotation is kept; for an upright ellipsoid (one axis along z) this is exactly the ellipsoid
    scaled by diag(horizontal, horizontal, vertical).
    """
    v = rotation[..., 2, :] ** 2
    if along is not None:
        v = np.where(np.any(along != 0.0, axis=-1)[..., None], np.einsum("...ji,...j->...i", rotation, along) ** 2, v)
    return vertical[..., None] ** v * horizontal[..., None] ** (1.0 - v)


def interpolate(reference, requests, metric="raw", power=DEFAULT_POWER, normalize=DEFAULT_NORMALIZE, weights=None):
    """Segmented IDW for a batch (B, 5) cm -> rotation (B, n, 3, 3), center (B, n, 3), semi_axes (B, n, 3).

    ``normalize="none"`` is the paper's Eq. 2.1 on the RMs' geometry; "height" and "proportional"
    average the geometry divided by each RM's scales and multiply the mean by the request's
    (module docstring). Rotations and weights are the same in all three. ``weights``: the requests'
    :func:`idw_weights` (same metric and power) when they are at hand, e.g. shared with the joints.
    """
    requests = np.atleast_2d(np.asarray(requests, dtype=float))
    if weights is None:
        weights = idw_weights(reference, requests, metric, power)  # (B, s, k)
    src = reference._source
    batch, n = requests.shape[0], len(reference.topology)
    rotation = np.empty((batch, n, 3, 3))
    center = np.empty((batch, n, 3))
    semi_axes = np.empty((batch, n, 3))
    # rotation_mean takes the k items on axis 0: rotations (k, 1, s, 3, 3), weights (k, B, s).
    rotation[:, src] = rotation_mean(reference.rotation[:, None, src], np.moveaxis(weights, -1, 0))
    if normalize == "none":
        center[:, src] = np.einsum("bsk,ksi->bsi", weights, reference.center[:, src])
        semi_axes[:, src] = np.einsum("bsk,ksi->bsi", weights, reference.semi_axes[:, src])
    else:
        ref_center, ref_semi = reference.normalized_geometry(normalize)
        horizontal, vertical = reference.size_scales(requests, normalize)  # (B, s)
        center[:, src] = scaled_points(np.einsum("bsk,ksji->bsji", weights, ref_center), horizontal, vertical)
        semi_axes[:, src] = np.einsum("bsk,ksi->bsi", weights, ref_semi) * axis_scale(
            rotation[:, src], horizontal, vertical, reference._limb_along
        )
    central, left, right = reference._central, reference._left, reference._right
    if len(central):
        rotation[:, central], center[:, central] = symmetrize_central(rotation[:, central], center[:, central])
    if len(left):
        rotation[:, right] = (SAGITTAL_REFLECTION @ rotation[:, left]) * reference._mirror_signs[:, None, :]
        center[:, right] = center[:, left] * np.array([-1.0, 1.0, 1.0])
        semi_axes[:, right] = semi_axes[:, left]
    return rotation, center, semi_axes


def interpolate_joints(reference, requests, metric, power, normalize, weights=None):
    """(B, 24, 3) joints of synthesized mannequins, or None if some Reference Mannequin has none: each left and
    central joint with its anchor part's IDW weights and proportional scales (as that part's centre; a joint below
    a limb's root anchored at the root and scaled in the limb's axes, as the limb's pieces), the right joints
    their mirror images. At an RM's measurements, that RM's joints. ``weights``: the requests'
    ``idw.idw_weights`` (same metric and power) when they are at hand, e.g. shared with the pieces'."""
    if reference.joints is None:
        return None
    topology = reference.topology
    anchors = anchor_indices(topology)
    source = {int(part): s for s, part in enumerate(reference._source)}
    own = [j for j, side in enumerate(JOINT_SIDES) if side != "R"]
    missing = [JOINT_NAMES[j] for j in own if int(anchors[j]) not in source]
    if missing:
        raise MannequinError(
            [
                Problem(
                    JOINT_ANCHORS[missing[0]],
                    "joints",
                    "anchor of a left or central joint must be a left or central part",
                )
            ]
        )
    slots = np.array([source[int(anchors[j])] for j in own])
    if weights is None:
        weights = idw_weights(reference, requests, metric, power)
    weights = weights[:, slots]  # (B, J, k)
    rm_joints = reference.joints[:, own]  # (k, J, 3)
    if normalize == "none":
        mean = _fixed_order_sum(weights, rm_joints)
    else:  # as the pieces: a joint below a limb's root is anchored at the root
        horizontal, vertical = reference.size_scales(np.atleast_2d(requests), normalize)
        parts = _fixed_order_sum(weights, reference.normalized_joints(normalize, own, slots))
        mean = scaled_points(parts, horizontal[:, slots], vertical[:, slots])
    out = np.empty((len(mean), JOINT_COUNT, 3))
    out[:, own] = mean
    return mirror_joints(out, "L")


def _fixed_order_sum(weights, values):
    """(B, J, ...) sum over k of weights (B, J, k) times values (k, J, ...), in a fixed order over runs of the
    rows' numbers: a row gets the same bits in any batch."""
    width = int(np.prod(values.shape[2:]))
    each = np.repeat(np.moveaxis(weights, -1, 0), width, axis=-1)  # (k, B, J * width): RM k's weight of each number
    flat = values.reshape(len(values), -1)
    total = np.zeros(each.shape[1:])
    for k in range(len(flat)):
        total += each[k] * flat[k]
    return total.reshape(len(weights), *values.shape[1:])
