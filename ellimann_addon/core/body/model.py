"""The body model: a request's measurements -> a body's vertices and joints, before the correction. One step,
replaceable (another model, e.g. a regression over many bodies, only needs ``body(request)`` -> (vertices,
joints)): the correction (core.body.correct) never looks inside it.

``IdwBodyModel``: the set's bodies averaged with inverse-distance weights of the request from each body's own
measurements (Eq. 2.1 as the pieces use it, over whole bodies; the distance in cm, or in the set's ranges with
``metric="normalized"``), power 2. Held out on the six female bodies (docs/body_skin.md) whole-body weights beat the
alternatives after the correction: ``segmented`` (tried, not the default: 0.826 against 0.842 mean IoU) is the pieces'
segmented IDW, each joint's bone takes its weights from the distance in its own measurements (the head and neck He; the
arms and collars He, Sh; the chest He, Br; the belly He, Wa; the pelvis and legs He, Hi: the shipped topology's
dependency of each part on its bone), bodies that coincide there sharing by their whole distance; a vertex's weights are
its bones' weighted by its bone weights (smooth: no seam). ``scale_height``: each body first scaled vertically to the
request's He (the pieces' proportional interpolation, for heights).
"""

import numpy as np

from ..mannequin.skeleton import JOINT_NAMES
from ..measurements import MEASUREMENTS

ZERO_DISTANCE = 1e-9  # closer than this is the body's own point
DEFAULT_POWER = 2.0  # the pieces' default (the paper's)
METRICS = ("raw", "normalized")
SUBSPACES = {  # the measurements each joint's bone is interpolated by (core.mannequin.topology's dependency)
    "Head": "He",
    "Neck": "He",
    "Spine3": "He Br",
    "Spine2": "He Br",
    "Spine1": "He Wa",
    "Pelvis": "He Hi",
    **{f"{s}_{j}": "He Sh" for s in "LR" for j in ("Collar", "Shoulder", "Elbow", "Wrist", "Hand")},
    **{f"{s}_{j}": "He Hi" for s in "LR" for j in ("Hip", "Knee", "Ankle", "Foot")},
}


def idw(distance, power):
    """Inverse-distance weights along the last axis; a zero distance takes all the weight (shared if several)."""
    distance = np.asarray(distance, float)
    zero = distance <= ZERO_DISTANCE
    nearest = np.where(zero, np.inf, distance).min(axis=-1, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        relative = np.where(zero, 0.0, (nearest / np.where(zero, 1.0, distance)) ** power)
    weights = np.where(zero.any(axis=-1, keepdims=True), zero.astype(float), relative)
    return weights / weights.sum(axis=-1, keepdims=True)


class IdwBodyModel:
    """Inverse-distance weighting over ``bodies`` (a core.body.bodies.SetBodies) by the five measurements."""

    def __init__(self, bodies, ranges=None, power=DEFAULT_POWER, metric="raw", scale_height=True, segmented=False):
        if metric not in METRICS:
            raise ValueError(f"metric: {metric!r} is not one of {', '.join(METRICS)}")
        self.bodies = bodies
        self.power = float(power)
        self.scale_height = bool(scale_height)
        self.segmented = bool(segmented)
        self.points = bodies.measured[:, : len(MEASUREMENTS)]
        if metric == "raw" or ranges is None:
            self.scale = np.ones(len(MEASUREMENTS))
        else:
            self.scale = np.array([max(ranges[k][1] - ranges[k][0], 1.0) for k in MEASUREMENTS])
        self.floors = np.array([bodies.vertices(i)[:, 2].min() for i in range(len(bodies))])
        self.mask = np.array([[key in SUBSPACES[name].split() for key in MEASUREMENTS] for name in JOINT_NAMES], float)
        diff = np.abs(self.points[:, None, :] - self.points[None, :, :])  # (N, N, 5)
        self.coincide = np.all((diff[None] <= ZERO_DISTANCE) | (self.mask[:, None, None, :] == 0.0), axis=-1)

    def joint_weights(self, request):
        """(24, N) each joint's bone's weights of the bodies (all rows alike unless ``segmented``)."""
        point = np.array([request[k] for k in MEASUREMENTS], float)
        diff = (self.points - point) / self.scale
        full = idw(np.sqrt(np.sum(diff * diff, axis=1)), self.power)
        if not self.segmented:
            return np.tile(full, (len(JOINT_NAMES), 1))
        sub = idw(np.sqrt((diff * diff) @ self.mask.T).T, self.power)  # (24, N)
        group = np.einsum("jnm,m->jn", self.coincide.astype(float), full)
        share = self.coincide.sum(axis=2) * full[None] / np.where(group > 0.0, group, 1.0)
        weights = sub * share
        return weights / weights.sum(axis=1, keepdims=True)

    def weights(self, request):
        """(N,) the bodies' weights for the whole body (the mean of the vertices' weights)."""
        return (self.bodies.dense_weights @ self.joint_weights(request)).mean(axis=0)

    def body(self, request):
        """(vertices (V, 3), joints (24, 3)) m: the bodies, each on the floor z = 0 and (``scale_height``)
        stretched to the request's He, blended for ``request``, the blend's lowest point on z = 0."""
        bodies = self.bodies
        per_joint = self.joint_weights(request)
        per_vertex = bodies.dense_weights @ per_joint  # (V, N)
        stretch = request["He"] / self.points[:, 0] if self.scale_height else np.ones(len(self.points))
        vertices = bodies.mean + np.einsum("vn,nvc->vc", per_vertex, bodies.offsets)
        # body n's z from its floor, stretched: (mean_z + offset_z - floor_n) * stretch_n
        vertical = per_vertex * stretch
        z = vertical.sum(axis=1) * bodies.mean[:, 2] + np.einsum("vn,nv->v", vertical, bodies.offsets[:, :, 2])
        z -= vertical @ self.floors
        floor = float(z.min())
        vertices[:, 2] = z - floor
        joints = np.einsum("jn,njc->jc", per_joint, bodies.joints)
        joints[:, 2] = np.einsum("jn,nj->j", per_joint * stretch, bodies.joints[:, :, 2] - self.floors[:, None]) - floor
        return vertices, joints

    def vertices(self, request):
        return self.body(request)[0]
