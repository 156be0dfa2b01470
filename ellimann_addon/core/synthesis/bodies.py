"""A reference set's bodies: the body meshes its RMs were traced from (one topology), stored compactly in the
set's folder as ``bodies.npz`` (docs/formats/bodies.md) and named by the manifest's ``bodies`` field:

    format, version        "ellimann-bodies", 1
    names (N,)             the RM stem each body belongs to
    mean (V, 3) float32    the bodies' mean, metres, ElliMann's axes (+X the body's left, -Y front, Z up)
    offsets (N, V, 3)      each body minus the mean, float16 (0.06 mm at most on the shipped bodies)
    faces (F, 3)           the shared triangles (uint16 below 65,536 vertices, else int32)
    region (V,) uint8      each vertex's region, an index into region_names (the arms: upper_arm, forearm, hand)
    joint_index (V, 4)     the four SMPL joints (core.mannequin.skeleton) each vertex follows most, uint8
    joint_weight (V, 4)    their linear-blend weights, float16, each row summing to 1
    joints (N, 24, 3)      each body's own joints, float32
    measured_cm (N, 11)    each body's measurements (the five and the six extras; NaN where not taken)
    fractions (4,)         the section heights (Sh, Br, Wa, Hi fractions of He) they were measured at

The bone weights are the body model's own (refmodels/skin_weights.npz, 104 bones) summed over the bones each
SMPL joint stands for (:func:`makehuman_joint`).
"""

import functools
import io
import json
import pathlib
import zipfile
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..constants import SECTION_FRACTIONS
from ..errors import ElliMannError
from ..files import atomic_write_bytes
from ..mannequin.joints import joints_from_makehuman
from ..mannequin.skeleton import JOINT_COUNT, JOINT_INDEX, JOINT_NAMES
from ..measure.body import check_mesh, measure_body_mesh
from ..measurements import ALL_MEASUREMENTS
from .manifest import read_manifest

BODIES_FILE = "bodies.npz"
SKELETON_FILE = "skeleton.json"  # a body model's joints, beside its bodies (skeleton_joints)
BODIES_FORMAT = "ellimann-bodies"
BODIES_VERSION = 1
WEIGHTS_PER_VERTEX = 4
ARM_REGIONS = ("upper_arm", "forearm", "hand")
FRACTION_KEYS = ("Sh", "Br", "Wa", "Hi")
MIN_BODIES = 2
MAX_OFFSET_M = 60.0  # float16's range is 65,504: an offset beyond this is no body of the set
RING_FACTOR, RING_MARGIN = 2.5, 0.01  # a regressed joint's vertices: within this times its nearest's distance, + m
REGRESSOR_RIDGE = np.sqrt(1e-5)  # its weights tied to the smallest by this
AFFINE_WEIGHT = 1e3  # its weights summing to 1 (an affine combination: the joint moves with the vertices)


class BodiesError(ElliMannError):
    """A set's bodies that cannot be used (another topology, wrong axes or units, a broken file), in one line."""


def makehuman_joint(bone):
    """The SMPL joint whose bone a MakeHuman bone is part of ('upperarm02.L' -> 'L_Shoulder'), or None; an SMPL
    joint's own name is itself (weights already on the 24 joints: a shipped set's)."""
    if bone in JOINT_INDEX:
        return bone
    name, _, side = bone.partition(".")
    central = {"root": "Pelvis", "pelvis": "Pelvis", "spine05": "Pelvis", "spine04": "Pelvis", "spine03": "Spine1"}
    central |= {"spine02": "Spine2", "spine01": "Spine3", "head": "Head", "eye": "Head"}
    if name in central:
        return central[name]
    if name.startswith("neck"):
        return "Neck"
    sided = (
        (("clavicle", "shoulder01"), "Collar"),
        (("upperarm",), "Shoulder"),
        (("lowerarm",), "Elbow"),
        (("wrist", "metacarpal", "finger1-"), "Wrist"),
        (("finger",), "Hand"),
        (("upperleg",), "Hip"),
        (("lowerleg",), "Knee"),
        (("foot",), "Ankle"),
        (("toe",), "Foot"),
    )
    for prefixes, joint in sided:
        if name.startswith(prefixes) and side in ("L", "R"):
            return f"{side}_{joint}"
    return None


def joint_weights(bone_indices, bone_weights, bone_labels, per_vertex=WEIGHTS_PER_VERTEX):
    """(joint index (V, k), weight (V, k)): a mesh's weights on MakeHuman bones summed over the SMPL joints'
    bones, the k largest kept and renormalized."""
    to_joint = np.array([JOINT_INDEX.get(makehuman_joint(str(b)), -1) for b in bone_labels])
    joint = to_joint[np.asarray(bone_indices)]
    if np.any((joint < 0) & (np.asarray(bone_weights) > 0.0)):
        unknown = sorted({str(bone_labels[b]) for b in np.asarray(bone_indices)[joint < 0]})
        raise BodiesError(f"bone weights: bones {', '.join(unknown[:4])} map to no SMPL joint")
    dense = np.zeros((len(joint), JOINT_COUNT))
    np.add.at(dense, (np.arange(len(joint))[:, None].repeat(joint.shape[1], 1), np.maximum(joint, 0)), bone_weights)
    order = np.argsort(-dense, axis=1, kind="stable")[:, :per_vertex]
    kept = np.take_along_axis(dense, order, axis=1)
    return order, kept / kept.sum(axis=1, keepdims=True)


@dataclass
class SetBodies:
    """N bodies of one topology: ``names`` (the RM each belongs to), ``mean`` (V, 3) and ``offsets`` (N, V, 3)
    metres, ``faces`` (F, 3), ``region`` (V,) into ``region_names``, the bone weights ``joint_index`` and
    ``joint_weight`` (V, 4) on the 24 SMPL joints, each body's ``joints`` (N, 24, 3) and ``measured`` (N, 11) cm
    (ALL_MEASUREMENTS, at the section heights ``fractions``)."""

    names: list
    mean: np.ndarray
    offsets: np.ndarray
    faces: np.ndarray
    region: np.ndarray
    region_names: tuple
    joint_index: np.ndarray
    joint_weight: np.ndarray
    joints: np.ndarray
    measured: np.ndarray
    fractions: dict

    def __len__(self):
        return len(self.names)

    def vertices(self, i):
        """Body i's vertices (V, 3) m."""
        return self.mean + self.offsets[i]

    def measurements(self, i):
        """Body i's measurements {key: cm} (those taken)."""
        return {key: float(v) for key, v in zip(ALL_MEASUREMENTS, self.measured[i]) if np.isfinite(v)}

    @cached_property
    def arms(self):
        """{"L", "R": (V,) bool}: the vertices of each arm (upper arm, forearm, hand), from the labels."""
        names = list(self.region_names)
        return {
            side: np.isin(self.region, [names.index(f"{r}_{side}") for r in ARM_REGIONS if f"{r}_{side}" in names])
            for side in ("L", "R")
        }

    @cached_property
    def dense_weights(self):
        """(V, 24) bone weights."""
        dense = np.zeros((len(self.mean), JOINT_COUNT))
        np.put_along_axis(dense, self.joint_index, self.joint_weight, axis=1)
        return dense

    def subset(self, keep):
        """The bodies at indices ``keep`` (a set without some of them: the held-out benchmark)."""
        keep = list(keep)
        return SetBodies(
            [self.names[i] for i in keep],
            self.mean,
            self.offsets[keep],
            self.faces,
            self.region,
            self.region_names,
            self.joint_index,
            self.joint_weight,
            self.joints[keep],
            self.measured[keep],
            self.fractions,
        )

    def to_bytes(self):
        """The .npz file's bytes (compressed)."""
        small = len(self.mean) < 65536
        arrays = {
            "format": np.array(BODIES_FORMAT),
            "version": np.array(BODIES_VERSION),
            "names": np.array(self.names),
            "mean": self.mean.astype(np.float32),
            "offsets": self.offsets.astype(np.float16),
            "faces": self.faces.astype(np.uint16 if small else np.int32),
            "region": self.region.astype(np.uint8),
            "region_names": np.array(self.region_names),
            "joint_index": self.joint_index.astype(np.uint8),
            "joint_weight": self.joint_weight.astype(np.float16),
            "joints": self.joints.astype(np.float32),
            "measured_cm": self.measured.astype(np.float32),
            "fractions": np.array([self.fractions[k] for k in FRACTION_KEYS]),
        }
        stream = io.BytesIO()
        np.savez_compressed(stream, **arrays)
        return stream.getvalue()

    def save(self, path):
        atomic_write_bytes(path, self.to_bytes())
        return pathlib.Path(path)


@dataclass(frozen=True)
class BodyLabels:
    """What a set's bodies carry besides their shape, for their topology: each vertex's ``region`` (V,) into
    ``region_names`` (the arms: ARM_REGIONS with _L/_R) and the body model's ``bones``: (bone indices (V, k),
    bone weights (V, k), bone labels) of MakeHuman's rig (or of the 24 SMPL joints, by their names); optionally
    a ``regressor`` (JointRegressor) giving the joints of a body that has none."""

    region: np.ndarray
    region_names: tuple
    bones: tuple
    regressor: object = None


class JointRegressor:
    """The 24 SMPL joints of a body of one topology from its vertices: each joint an affine combination of the
    vertices about it (within RING_FACTOR times its nearest's distance, plus RING_MARGIN, on the bodies' mean),
    fitted by least squares to bodies whose joints are known, tied by a small ridge (REGRESSOR_RIDGE) to the
    smallest weights. On the 160 bank bodies (../shared/bodies), fitted to the shipped sets' ten: each body's
    worst joint 1.1-1.3 cm off at the median, 5 cm at worst (the spine, which the body model sets apart from
    the surface)."""

    def __init__(self, vertices, joints):
        vertices, joints = np.asarray(vertices, float), np.asarray(joints, float)
        mean, centre = vertices.mean(axis=0), joints.mean(axis=0)
        self.rows, self.weights = [], []
        for j in range(JOINT_COUNT):
            distance = np.linalg.norm(mean - centre[j], axis=1)
            near = np.nonzero(distance <= RING_FACTOR * distance.min() + RING_MARGIN)[0]
            system = np.vstack(
                [np.concatenate([vertices[:, near, c] for c in range(3)]), REGRESSOR_RIDGE * np.eye(len(near))]
                + [AFFINE_WEIGHT * np.ones((1, len(near)))]
            )
            target = np.concatenate([joints[:, j, c] for c in range(3)] + [np.zeros(len(near)), [AFFINE_WEIGHT]])
            self.rows.append(near)
            self.weights.append(np.linalg.lstsq(system, target, rcond=None)[0])

    def __call__(self, vertices):
        """(24, 3) the joints of a body's ``vertices`` (V, 3)."""
        vertices = np.asarray(vertices, float)
        return np.array([w @ vertices[rows] for rows, w in zip(self.rows, self.weights)])


def shipped_topology_labels(faces):
    """BodyLabels of the shipped sets' bodies' topology (their region labels, their bone weights on the 24
    joints, a JointRegressor fitted to their bodies) when ``faces`` are its triangles, else None: the labels of a
    body the shipped body model made, known without a labels file."""
    faces = np.asarray(faces)
    known = shipped_bodies()
    if not known or known[0].faces.shape != faces.shape or not np.array_equal(known[0].faces, faces):
        return None
    first = known[0]
    vertices = np.concatenate([[b.vertices(i) for i in range(len(b))] for b in known])
    joints = np.concatenate([b.joints for b in known])
    bones = (first.joint_index, first.joint_weight, JOINT_NAMES)
    return BodyLabels(first.region, first.region_names, bones, JointRegressor(vertices, joints))


@functools.cache
def shipped_bodies():
    """The shipped sets' SetBodies of one topology, each body once (the female and male sets'; the fine sets
    carry the same bodies)."""
    from .shipped import SHIPPED_SETS

    found, seen = [], set()
    for folder in SHIPPED_SETS.values():
        bodies = load_set_bodies(folder)
        if bodies is None or (found and not np.array_equal(bodies.faces, found[0].faces)):
            continue
        keep = [i for i in range(len(bodies)) if bodies.vertices(i).tobytes() not in seen]
        seen.update(bodies.vertices(i).tobytes() for i in keep)
        if keep:
            found.append(bodies.subset(keep))
    return tuple(found)


def skeleton_joints(path):
    """{body name: (24, 3) SMPL joints} from a body model's skeleton file (../shared/refmodels/skeleton.json:
    each body's MakeHuman bone heads, ElliMann's axes, metres), {} when there is no such file; BodiesError (one
    line) for one that cannot be read."""
    path = pathlib.Path(path)
    if not path.is_file():
        return {}
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        found = {name: joints_from_makehuman(bones) for name, bones in data["bodies"].items()}
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as error:
        raise BodiesError(f"{path}: cannot be read as a skeleton file ({error})") from None
    for name, joints in found.items():
        if joints.shape != (JOINT_COUNT, 3) or not np.all(np.isfinite(joints)):
            raise BodiesError(f"{path}: body {name}: its joints are not 24 finite points")
    return found


def from_meshes(names, vertices, faces, region, region_names, weights, joints, fractions=None):
    """SetBodies of N bodies (``vertices`` (N, V, 3) m, ElliMann's axes, sharing ``faces``): each one's
    measurements taken by core.measure.body with the arms known from ``region``; ``weights``: (bone indices
    (V, k), bone weights (V, k), bone labels) of MakeHuman's rig, mapped on the SMPL joints; ``joints`` (N, 24, 3).
    BodiesError (one line) for bodies of another topology, in the wrong axes or units, or labels that do not fit."""
    fractions = dict(fractions or SECTION_FRACTIONS)
    vertices = np.asarray(vertices, float)
    faces = np.asarray(faces, np.int64)
    check_bodies(names, vertices, faces, region, region_names, joints)
    joint_index, joint_weight = joint_weights(*weights)
    mean = vertices.mean(axis=0)
    bodies = SetBodies(
        list(names),
        mean,
        (vertices - mean).astype(np.float32),
        faces,
        np.asarray(region, np.int64),
        tuple(str(n) for n in region_names),
        joint_index,
        joint_weight,
        np.asarray(joints, float),
        np.zeros((len(names), len(ALL_MEASUREMENTS))),
        fractions,
    )
    for i in range(len(names)):
        found = measure_body_mesh(vertices[i], faces, fractions, arms=bodies.arms).values
        bodies.measured[i] = [found.get(key, np.nan) for key in ALL_MEASUREMENTS]
    return bodies


def check_bodies(names, vertices, faces, region, region_names, joints):
    """BodiesError (one line, naming the body) for bodies that cannot make a body skin."""
    if len(names) < MIN_BODIES or len(vertices) != len(names) or len(joints) != len(names):
        raise BodiesError(f"bodies: need at least {MIN_BODIES}, each with its vertices and joints")
    count = vertices.shape[1]
    if faces.ndim != 2 or faces.shape[1] != 3 or faces.min() < 0 or faces.max() >= count:
        raise BodiesError(f"faces: must be (F, 3) vertex indices below {count}")
    if len(region) != count:
        raise BodiesError(f"region labels: {len(region)} labels for {count} vertices (another topology)")
    if np.asarray(joints).shape[1:] != (JOINT_COUNT, 3):
        raise BodiesError(f"joints: must be ({JOINT_COUNT}, 3) per body (the SMPL joints)")
    left = [region_names.index(f"{r}_L") for r in ARM_REGIONS if f"{r}_L" in region_names]
    if not left:
        raise BodiesError(f"region labels: no arm regions ({', '.join(r + '_L' for r in ARM_REGIONS)})")
    for name, body, skeleton in zip(names, vertices, joints):
        fatal = check_mesh(body, faces)
        if fatal:
            raise BodiesError(f"body {name}: {fatal}")
        if np.abs(body - vertices.mean(axis=0)).max() > MAX_OFFSET_M:
            raise BodiesError(f"body {name}: lies {MAX_OFFSET_M:g} m or more from the others (another unit?)")
        if body[np.isin(region, left), 0].mean() <= 0.0:
            raise BodiesError(f"body {name}: its left arm is not on +X (ElliMann's axes: +X the body's left)")
        ankle, toes = skeleton[JOINT_INDEX["L_Ankle"]], skeleton[JOINT_INDEX["L_Foot"]]
        if toes[1] >= ankle[1]:
            raise BodiesError(f"body {name}: its toes point to +Y (ElliMann's bodies face -Y)")


def read_versioned_npz(path, what, format_name, newest):
    """{name: array} of an .npz file whose ``format`` is ``format_name`` and ``version`` 1 to ``newest``;
    BodiesError naming the file and what is wrong (``what``: "a bodies file")."""
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {key: data[key] for key in data.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as error:
        raise BodiesError(f"{path}: cannot be read as {what} ({error})") from None
    if str(arrays.get("format", "")) != format_name:
        raise BodiesError(f"{path}: format is not '{format_name}'")
    version = int(arrays.get("version", -1))
    if not 1 <= version <= newest:
        raise BodiesError(f"{path}: version {version}; this ElliMann reads versions 1 to {newest}")
    return arrays


def read_bodies(path):
    """SetBodies from a ``bodies.npz`` file; BodiesError naming the file and what is wrong."""
    path = pathlib.Path(path)
    arrays = read_versioned_npz(path, "a bodies file", BODIES_FORMAT, BODIES_VERSION)
    try:
        names = [str(n) for n in arrays["names"]]
        mean = arrays["mean"].astype(float)
        offsets = arrays["offsets"].astype(np.float32)
        faces = arrays["faces"].astype(np.int64)
        count = len(mean)
        shapes = {
            "offsets": (offsets.shape, (len(names), count, 3)),
            "faces": (faces.shape[1:], (3,)),
            "region": (arrays["region"].shape, (count,)),
            "joint_index": (arrays["joint_index"].shape, (count, WEIGHTS_PER_VERTEX)),
            "joint_weight": (arrays["joint_weight"].shape, (count, WEIGHTS_PER_VERTEX)),
            "joints": (arrays["joints"].shape, (len(names), JOINT_COUNT, 3)),
            "measured_cm": (arrays["measured_cm"].shape, (len(names), len(ALL_MEASUREMENTS))),
            "fractions": (arrays["fractions"].shape, (len(FRACTION_KEYS),)),
        }
    except KeyError as error:
        raise BodiesError(f"{path}: has no {error.args[0]} array") from None
    for key, (shape, wanted) in shapes.items():
        if tuple(shape) != wanted:
            raise BodiesError(f"{path}: {key} has shape {tuple(shape)}, expected {wanted}")
    if faces.min() < 0 or faces.max() >= count or not np.all(np.isfinite(offsets)):
        raise BodiesError(f"{path}: faces index no vertex or offsets are not finite")
    weight = arrays["joint_weight"].astype(float)
    if arrays["joint_index"].max() >= JOINT_COUNT or np.abs(weight.sum(axis=1) - 1.0).max() > 1e-2:
        raise BodiesError(f"{path}: joint weights must index the {JOINT_COUNT} joints and sum to 1 per vertex")
    return SetBodies(
        names,
        mean,
        offsets,
        faces,
        arrays["region"].astype(np.int64),
        tuple(str(n) for n in arrays["region_names"]),
        arrays["joint_index"].astype(np.int64),
        weight / weight.sum(axis=1, keepdims=True),
        arrays["joints"].astype(float),
        arrays["measured_cm"].astype(float),
        dict(zip(FRACTION_KEYS, (float(f) for f in arrays["fractions"]))),
    )


def labelled_arms(faces):
    """{"L", "R": (V,) bool} the arms' vertices of a mesh whose triangles are the shipped bodies' own (a body of
    the body model, a body skin, a scan's twin), from their labels; None for any other mesh, whose arms the
    measurer finds by their geometry."""
    faces = np.asarray(faces)
    known = shipped_bodies()
    if not known or known[0].faces.shape != faces.shape or not np.array_equal(known[0].faces, faces):
        return None
    return known[0].arms


def load_set_bodies(folder):
    """The SetBodies of a reference-set folder, or None for a set without bodies (an old folder, a hand-traced
    set); BodiesError for a manifest that names a bodies file that cannot be read."""
    folder = pathlib.Path(folder)
    manifest = read_manifest(folder)
    if manifest is None or manifest.bodies is None:
        return None
    path = folder / manifest.bodies
    if not path.is_file():
        raise BodiesError(f"{path}: is missing (the manifest names it as the set's bodies)")
    return read_bodies(path)
