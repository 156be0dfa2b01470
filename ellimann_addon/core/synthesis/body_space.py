"""A reference set's body space (``body_space.npz``, docs/formats/body_space.md): what a linear body model
(core.body.ridge) needs of many bodies of one topology, kept compactly beside the set's RMs and named by the
manifest's optional ``body_space`` field.

Ridge regression from the standardized measurements X (N, M) to the bodies Y (N, P: each body's vertices on its
floor, then its 24 joints, flattened) predicts ``mean + Yc^T Xs_S (Xs_S^T Xs_S + P_S)^-1 xs_S`` for any subset S of
the measurements and any diagonal penalty P_S. With Xs = Q R (Q orthonormal, N x M) that is ``mean +
(Q^T Yc)^T R_S (R_S^T R_S + P_S)^-1 xs_S``: the M meshes ``directions = Q^T Yc`` and the small R hold every model
(any subset of the measurements given, any tolerances), exactly; the bodies' Gram matrix ``Yc Yc^T`` (N, N) adds
their leave-one-out errors (cross-validation) in closed form. The bodies themselves are not stored.

    format, version     "ellimann-body-space", 1
    names (N,)          the bodies it was made from
    keys (M,)           the measurements (inputs), SPACE_MEASUREMENTS
    measured_cm (N, M)  each body's measurements (by core.measure.body and core.measure.further)
    centre, scale (M,)  their mean and standard deviation over the bodies (what standardizes a request)
    r (K, M)            R of the QR decomposition of the standardized measurements (K = min(N, M))
    mean (P,) float32   the bodies' mean (vertices on the floor, then joints), metres
    directions (K, P)   Q^T Yc, float16
    gram (N, N)         Yc Yc^T (m^2)
    vertex_count        V (P = 3 V + 72)
    fractions (4,)      the section heights (Sh, Br, Wa, Hi fractions of He) the measurements were taken at
"""

import io
import pathlib
from dataclasses import dataclass

import numpy as np

from ..constants import GIRTHS
from ..files import atomic_write_bytes
from ..mannequin.skeleton import JOINT_COUNT
from ..measure.body import check_mesh, measure_body_mesh, section_blobs
from ..measure.further import FURTHER_MEASUREMENTS, measure_further
from ..measurements import ALL_MEASUREMENTS
from .bodies import FRACTION_KEYS, BodiesError, check_bodies, read_versioned_npz
from .manifest import read_manifest

SPACE_FILE = "body_space.npz"
SPACE_FORMAT = "ellimann-body-space"
SPACE_VERSION = 1
SPACE_MEASUREMENTS = ALL_MEASUREMENTS + FURTHER_MEASUREMENTS
MIN_SPACE_BODIES = 10  # below this IDW over the bodies does as well (docs/body_space.md)
DUPLICATE_M = 1e-3  # two bodies whose every vertex lies within 1 mm are one body twice


@dataclass
class BodySpace:
    """The sufficient statistics of ridge regressions from measurements to bodies (module docstring)."""

    names: list
    keys: tuple
    measured: np.ndarray
    centre: np.ndarray
    scale: np.ndarray
    r: np.ndarray
    mean: np.ndarray
    directions: np.ndarray
    gram: np.ndarray
    vertex_count: int
    fractions: dict

    def __len__(self):
        return len(self.names)

    @property
    def standardized(self):
        """(N, M) the bodies' standardized measurements."""
        return (self.measured - self.centre) / self.scale

    def split(self, flat):
        """(vertices (V, 3), joints (24, 3)) of a flat output (P,)."""
        count = 3 * self.vertex_count
        return flat[:count].reshape(-1, 3), flat[count:].reshape(JOINT_COUNT, 3)

    def to_bytes(self):
        arrays = {
            "format": np.array(SPACE_FORMAT),
            "version": np.array(SPACE_VERSION),
            "names": np.array(self.names),
            "keys": np.array(self.keys),
            "measured_cm": self.measured.astype(np.float64),
            "centre": self.centre.astype(np.float64),
            "scale": self.scale.astype(np.float64),
            "r": self.r.astype(np.float64),
            "mean": self.mean.astype(np.float32),
            "directions": self.directions.astype(np.float16),
            "gram": self.gram.astype(np.float64),
            "vertex_count": np.array(self.vertex_count),
            "fractions": np.array([self.fractions[k] for k in FRACTION_KEYS]),
        }
        stream = io.BytesIO()
        np.savez_compressed(stream, **arrays)
        return stream.getvalue()

    def save(self, path):
        atomic_write_bytes(path, self.to_bytes())
        return pathlib.Path(path)


def flat_bodies(vertices, joints):
    """(N, P): each body's vertices on its floor (z from its lowest vertex), then its joints alike, flattened."""
    vertices = np.array(vertices, float)
    joints = np.array(joints, float)
    floors = vertices[:, :, 2].min(axis=1)
    vertices[:, :, 2] -= floors[:, None]
    joints[:, :, 2] -= floors[:, None]
    return np.concatenate([vertices.reshape(len(vertices), -1), joints.reshape(len(joints), -1)], axis=1)


def space_from_arrays(names, vertices, joints, measured, fractions, keys=SPACE_MEASUREMENTS):
    """The BodySpace of N bodies (``vertices`` (N, V, 3) m, ``joints`` (N, 24, 3)) and their ``measured`` (N, M)
    cm of ``keys``. BodiesError for too few bodies or measurements that are not finite."""
    measured = np.asarray(measured, float)
    if len(names) < MIN_SPACE_BODIES:
        raise BodiesError(f"body space: needs at least {MIN_SPACE_BODIES} bodies, got {len(names)}")
    if measured.shape != (len(names), len(keys)) or not np.all(np.isfinite(measured)):
        raise BodiesError(f"body space: measurements must be ({len(names)}, {len(keys)}) finite values (cm)")
    flat = flat_bodies(vertices, joints)
    mean = flat.mean(axis=0)
    centred = flat - mean
    centre, scale = measured.mean(axis=0), measured.std(axis=0)
    scale = np.where(scale > 0.0, scale, 1.0)
    q, r = np.linalg.qr((measured - centre) / scale)
    return BodySpace(
        [str(n) for n in names],
        tuple(keys),
        measured,
        centre,
        scale,
        r,
        mean,
        q.T @ centred,
        centred @ centred.T,
        int(np.asarray(vertices).shape[1]),
        dict(fractions),
    )


def measure_for_space(vertices, faces, fractions, arms):
    """({key: cm} of SPACE_MEASUREMENTS taken, [problems]) of one body, its arms known (``arms``)."""
    found = measure_body_mesh(vertices, faces, fractions, arms=arms)
    further, problems = measure_further(vertices, faces, fractions, arms)
    return {**found.values, **further}, found.problems + problems


def space_from_meshes(names, vertices, faces, region, region_names, joints, fractions, progress=None):
    """The BodySpace of a bank of bodies (``vertices`` (N, V, 3) m sharing ``faces``, ``joints`` (N, 24, 3)), each
    measured with its arms known from ``region``. BodiesError (one line, naming the body) for a body of another
    topology, in the wrong axes or units (core.synthesis.bodies.check_bodies), a body given twice, or one whose
    measurements cannot all be taken (arms against the torso at a section). ``progress(done, total, name)``."""
    vertices = np.asarray(vertices, float)
    faces = np.asarray(faces, np.int64)
    if vertices.ndim != 3 or len(region) != vertices.shape[1]:
        count = vertices.shape[1] if vertices.ndim == 3 else "?"
        raise BodiesError(f"body space: the bodies have {count} vertices, the labels {len(region)} (another topology)")
    for name, body in zip(names, vertices):  # each alone first: one body in millimetres skews the bodies' mean
        fatal = check_mesh(body, faces)
        if fatal:
            raise BodiesError(f"body {name}: {fatal}")
    check_bodies(names, vertices, faces, region, list(region_names), joints)
    duplicate_bodies(names, vertices)
    names_list = list(region_names)
    arms = {
        side: np.isin(region, [names_list.index(n) for n in names_list if n.endswith(f"_{side}") and _arm(n)])
        for side in ("L", "R")
    }
    for name, body in zip(names, vertices):
        fused = fused_sections(body, faces, arms["L"] | arms["R"], fractions)
        if fused:
            raise BodiesError(
                f"body {name}: an arm touches the torso at the {', '.join(fused)} section: "
                f"{', '.join(fused)} cannot be measured (the arms must hang clear of the torso)"
            )
    measured = np.zeros((len(names), len(SPACE_MEASUREMENTS)))
    for i, name in enumerate(names):
        values, problems = measure_for_space(vertices[i], faces, fractions, arms)
        missing = [key for key in SPACE_MEASUREMENTS if key not in values]
        if missing:
            why = f" ({problems[0]})" if problems else ""
            raise BodiesError(f"body {name}: {', '.join(missing)} cannot be measured{why}")
        measured[i] = [values[key] for key in SPACE_MEASUREMENTS]
        if progress is not None:
            progress(i + 1, len(names), name)
    return space_from_arrays(names, vertices, joints, measured, fractions)


def fused_sections(vertices, faces, arm, fractions):
    """The girth sections (Br, Wa, Hi) where a loop of an arm's triangles and one of the torso's touch or overlap
    (one blob of core.measure.body.section_blobs holds both): an arm against the torso there."""
    bottom = vertices[:, 2].min()
    height = np.ptp(vertices[:, 2])
    arm_face = arm[faces].all(axis=1)
    torso_face = ~arm[faces].any(axis=1)
    fused = []
    for key in GIRTHS:
        segments, rows, blob = section_blobs(vertices, faces, bottom + fractions[key] * height)
        mixed = [b for b in np.unique(blob) if arm_face[rows[blob == b]].any() and torso_face[rows[blob == b]].any()]
        if mixed:
            fused.append(key)
    return fused


def _arm(region_name):
    return region_name.rsplit("_", 1)[0] in ("upper_arm", "forearm", "hand")


def duplicate_bodies(names, vertices, within=DUPLICATE_M):
    """BodiesError naming the first two bodies whose every vertex lies within ``within`` m of the other's."""
    flat = vertices.reshape(len(vertices), -1)
    centred = flat - flat.mean(axis=0)
    gram = centred @ centred.T
    square = np.diag(gram)[:, None] + np.diag(gram)[None, :] - 2.0 * gram
    count = vertices.shape[1]
    for i, j in zip(*np.nonzero(np.triu(square <= count * within**2 * (1.0 + 1e-6), 1))):
        if np.linalg.norm(vertices[i] - vertices[j], axis=1).max() <= within:
            raise BodiesError(
                f"bodies {names[i]} and {names[j]}: the same body twice (every vertex within {within * 1e3:g} mm)"
            )


def read_body_space(path):
    """BodySpace from a ``body_space.npz`` file; BodiesError naming the file and what is wrong."""
    path = pathlib.Path(path)
    arrays = read_versioned_npz(path, "a body-space file", SPACE_FORMAT, SPACE_VERSION)
    try:
        names, keys = [str(n) for n in arrays["names"]], tuple(str(k) for k in arrays["keys"])
        count = int(arrays["vertex_count"])
        n, m, p = len(names), len(keys), 3 * count + 3 * JOINT_COUNT
        k = min(n, m)  # the rank of the QR decomposition's factors
        shapes = {
            "measured_cm": (n, m),
            "centre": (m,),
            "scale": (m,),
            "r": (k, m),
            "mean": (p,),
            "directions": (k, p),
            "gram": (n, n),
            "fractions": (len(FRACTION_KEYS),),
        }
        for key, wanted in shapes.items():
            if arrays[key].shape != wanted:
                raise BodiesError(f"{path}: {key} has shape {arrays[key].shape}, expected {wanted}")
    except KeyError as error:
        raise BodiesError(f"{path}: has no {error.args[0]} array") from None
    unknown = [key for key in keys if key not in SPACE_MEASUREMENTS]
    if unknown:
        raise BodiesError(f"{path}: {', '.join(unknown)} is no measurement ElliMann takes")
    floats = [arrays[key].astype(float) for key in ("measured_cm", "centre", "scale", "r", "mean", "gram")]
    directions = arrays["directions"].astype(np.float32)
    if not all(np.all(np.isfinite(a)) for a in floats) or not np.all(np.isfinite(directions)) or floats[2].min() <= 0:
        raise BodiesError(f"{path}: values that are not finite (or a measurement's scale not positive)")
    measured, centre, scale, r, mean, gram = floats
    fractions = dict(zip(FRACTION_KEYS, (float(f) for f in arrays["fractions"])))
    return BodySpace(names, keys, measured, centre, scale, r, mean, directions, gram, count, fractions)


def load_set_body_space(folder):
    """The BodySpace of a reference-set folder, or None for a set without one (an old folder, a set of a few
    bodies); BodiesError for a manifest that names a file that cannot be read."""
    folder = pathlib.Path(folder)
    manifest = read_manifest(folder)
    name = None if manifest is None else getattr(manifest, "body_space", None)
    if name is None:
        return None
    path = folder / name
    if not path.is_file():
        raise BodiesError(f"{path}: is missing (the manifest names it as the set's body space)")
    return read_body_space(path)
