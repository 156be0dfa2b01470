"""An avatar for garment tools (CLO, Marvelous Designer, Browzwear, game engines): a mannequin's skin as one
linearly skinned mesh on the 24 SMPL bones, in the rest pose the tool wants (the A-pose the bodies stand in, or a
T-pose), under at most a triangle budget, and measured again as it is written. The arrays only: Blender's FBX
exporter writes them (``blender.services.fbx``).

- the bones' names: SMPL's (``L_Hip``) or Mixamo's (``mixamorig:LeftUpLeg``, from ``core.pose.rig_names``);
- the weights: the skin's linear-blend weights (``Skin.bones``) as a dense (V, 24) table, which a decimation
  interpolates like any vertex attribute;
- the pose: a T-pose moves the skin by linear-blend skinning (``Skin.posed``'s formula on the dense table) and the
  mannequin's pieces and joints rigidly with their bones (``pose_mannequin``), so the written rest pose is the
  T-pose and the skeleton's bones start at the posed joints;
- the measurements: a decimated skin is measured again as its own mesh in the A-pose, where they are defined: a
  skin over the pieces by ``core.skin.measure`` (each vertex takes the pieces of the nearest vertex of the skin it
  was decimated from), the body skin (``core.body.skin.BodySkin``) by the body-mesh measurer
  (``core.measure.body.measure_body_mesh``) with its arms carried over the same way from the labels; it must still
  meet the request within ``DECIMATED_TOLERANCE_CM`` of each measurement.

How a job asks for an avatar (``core.job.request.Request.avatar``, the format table's ``fbx`` row): an
:class:`AvatarOptions` (the pose, the bones' names, the proxy, the triangle budget).
"""

from dataclasses import dataclass

import numpy as np

from ..errors import ElliMannError
from ..geometry.ellipsoid import matrix_world
from ..geometry.mesh import icosphere
from ..mannequin.skeleton import JOINT_COUNT, JOINT_NAMES, part_bones
from ..measure.body import measure_body_mesh
from ..pose.kinematics import bone_matrices, pose_mannequin
from ..pose.motion import clamped_motion
from ..pose.rig_names import RIG_NAME_MAPS
from ..settings import AVATAR_MIN_TRIANGLES, AVATAR_POSES, AVATAR_TRIANGLES, BONE_NAMINGS
from ..skin.measure import body_measurements, mesh_measurements
from ..skin.surface import Skin

GARMENT_TOOL_TRIANGLES = AVATAR_TRIANGLES  # CLO's import guidance for an avatar: at most about 70k triangles
DECIMATED_TOLERANCE_CM = 0.2  # a decimated avatar meets every requested measurement within 2 mm
MIXAMO_PREFIX = "mixamorig:"
PROXY_LEVEL = 2  # icosphere level of a piece in the collision proxy (320 triangles each)
MIN_TRIANGLES = AVATAR_MIN_TRIANGLES  # a smaller budget leaves no body to measure


def bone_names(naming="smpl"):
    """The 24 bones' names in joint order: SMPL's (``JOINT_NAMES``) or Mixamo's, prefixed ``mixamorig:`` as
    Mixamo's own FBX files name them."""
    if naming not in BONE_NAMINGS:
        raise ElliMannError(f"bone names: {naming!r} is not one of {', '.join(BONE_NAMINGS)}")
    if naming == "smpl":
        return list(JOINT_NAMES)
    found = {}
    for name, joint in RIG_NAME_MAPS["mixamo"].items():
        found.setdefault(joint, MIXAMO_PREFIX + name)
    missing = [joint for joint in JOINT_NAMES if joint not in found]
    if missing:  # the table is the core's: a joint it lacks is a bug, named
        raise ElliMannError(f"bone names: Mixamo's table has no name for {missing[0]}")
    return [found[joint] for joint in JOINT_NAMES]


def dense_weights(skin):
    """(V, 24): each vertex's linear-blend weight on every bone (rows sum to 1)."""
    bones, weights = skin.bones()
    table = np.zeros((len(skin.vertices), JOINT_COUNT))
    np.add.at(table, (np.repeat(np.arange(len(bones)), bones.shape[1]), bones.ravel()), weights.ravel())
    return table


def check_avatar_options(pose, naming, max_triangles):
    """ElliMannError (one line) for a pose, a bone naming or a triangle budget ElliMann does not write."""
    if pose not in AVATAR_POSES:
        raise ElliMannError(f"pose: {pose!r} is not one of {', '.join(AVATAR_POSES)}")
    bone_names(naming)
    if max_triangles is not None and (
        isinstance(max_triangles, bool) or not isinstance(max_triangles, int) or max_triangles < MIN_TRIANGLES
    ):
        raise ElliMannError(f"triangles: the budget must be a whole number of at least {MIN_TRIANGLES:,}")


@dataclass(frozen=True)
class AvatarOptions:
    """How an avatar is written (the format table's ``fbx`` row): its rest ``pose`` (a_pose, t_pose), the bones'
    names (``naming``: smpl, mixamo), the pieces beside it as a collision ``proxy``, the skin's triangle budget
    (``max_triangles``; None: as it is). ``request`` {key: cm}: what it must still measure once decimated (a job
    fills it from its result: ``core.job.result.Result.avatar_request``); ``told(FbxAvatar)``: called with what
    each file holds (a caller's report), if given."""

    pose: str = "a_pose"
    naming: str = "smpl"
    proxy: bool = False
    max_triangles: int | None = GARMENT_TOOL_TRIANGLES
    request: dict | None = None
    told: object = None

    def checked(self):
        """Itself, or ElliMannError (one line) for an option ElliMann does not write."""
        check_avatar_options(self.pose, self.naming, self.max_triangles)
        return self


def blend(vertices, weights, matrices):
    """Linear-blend skinning with a dense table: sum_j weights[:, j] (R_j v + t_j), ``matrices`` (24, 3, 4)."""
    moved = np.einsum("jik,vk->vji", matrices[:, :, :3], vertices) + matrices[:, :, 3]
    return np.einsum("vj,vji->vi", weights, moved)


@dataclass
class PosedAvatar:
    """The avatar in its written rest pose: the mannequin (pieces and joints posed), the skin's vertices, the
    pose's clamp reports (a joint the pose could not reach)."""

    mannequin: object
    vertices: np.ndarray
    reports: list


def posed_avatar(mannequin, vertices, weights, pose="a_pose"):
    """The avatar of ``mannequin`` whose skin is ``vertices`` (V, 3) with ``weights`` (V, 24), in ``pose``
    (``a_pose``: as it stands; ``t_pose``: arms out level, each joint angle clamped into its range)."""
    check_avatar_options(pose, "smpl", None)
    if pose == "a_pose":
        return PosedAvatar(mannequin, np.asarray(vertices, float), [])
    poses, reports, _ = clamped_motion(pose, mannequin.joints)
    matrices = bone_matrices(mannequin.joints, poses[0])[:, :3, :]
    return PosedAvatar(pose_mannequin(mannequin, poses[0]), blend(vertices, weights, matrices), reports)


def proxy_mesh(mannequin, level=PROXY_LEVEL):
    """The pieces as one collision proxy: (vertices, faces, bone of each vertex): each ellipsoid an icosphere at
    ``level`` (inside its ellipsoid), riding on its part's bone."""
    unit, faces = icosphere(level)
    matrices = matrix_world(mannequin.rotation, mannequin.center, mannequin.semi_axes)
    count = len(matrices)
    vertices = np.einsum("nij,vj->nvi", matrices[:, :3, :3], unit) + matrices[:, None, :3, 3]
    bones = np.repeat(part_bones(mannequin.topology), len(unit))
    offsets = (np.arange(count) * len(unit))[:, None, None]
    return vertices.reshape(-1, 3), (faces[None] + offsets).reshape(-1, 3), bones


def remeasure(skin, vertices, faces, nearest):
    """({key: cm}, problems) of a decimated skin's mesh (``vertices``, ``faces``), each vertex taking what it needs
    from the vertex ``nearest`` (V,) of ``skin`` it lies closest to. A skin over the pieces
    (``core.skin.surface.Skin``): its pieces, measured as that skin (core.skin.measure: the five by
    mesh_measurements, the six extra ones by body_measurements). The body skin (``core.body.skin.BodySkin``, which
    has no pieces): its arms from the labels, measured as the body skin measures itself (``measure_body_mesh`` at its
    set's heights, the neck where a tape settles, as ``measure`` reads a scan)."""
    nearest = np.asarray(nearest, dtype=np.int64)
    if not hasattr(skin, "pieces"):
        arms = {side: np.asarray(skin.arms[side], bool)[nearest] for side in ("L", "R")}
        vertices, faces = np.asarray(vertices, float), np.asarray(faces, np.int64)
        found = measure_body_mesh(vertices, faces, skin.bodies.fractions, None, arms)
        return dict(found.values), list(found.problems)
    decimated = Skin(
        skin.mannequin,
        np.asarray(vertices, float),
        np.asarray(faces, np.int64),
        skin.pieces[nearest],
        skin.weights[nearest],
        skin.settings,
    )
    five = mesh_measurements(decimated)
    measured = body_measurements(decimated)
    return {**measured.values, **five}, measured.problems


def misses(measured, request, tolerance_cm=DECIMATED_TOLERANCE_CM):
    """[(key, measured - requested cm)] of the requested measurements ``measured`` misses by more than
    ``tolerance_cm``, the worst first (a measurement that could not be taken is a miss of nan)."""
    found = []
    for key, value in request.items():
        got = measured.get(key)
        off = float("nan") if got is None or not np.isfinite(got) else float(got - value)
        if not abs(off) <= tolerance_cm:
            found.append((key, off))
    return sorted(found, key=lambda item: -abs(item[1]) if np.isfinite(item[1]) else -np.inf)
