"""Mannequin files the core writes without Blender: OBJ (Y up), ElliMann's JSON and MJCF (MuJoCo's XML), at rest or
posed, with a skin or not: the writers of those rows of ``core.formats.table``, each writing one mannequin to
paths of its format, atomically.

With a ``skin``: the .obj holds the skin alone, the .json records how it was made (its ``skin`` section), the MJCF
draws it over the pieces. Posed (``frames``, a list of ``core.pose.kinematics.Pose``): the .json is the rest
mannequin with a ``pose`` section (``core.formats.posed_files``), the .xml an articulated body with the frames as
keyframes, the .obj the posed pieces (or skin) of a still pose.
"""

import json

import numpy as np

from ..errors import ElliMannError
from ..files import atomic_write_text
from .mjcf import write_mjcf
from .obj import write_obj, write_skin_obj
from .posed_files import pose_section


def write_json_files(mannequin, paths, *, skin=None, frames=None, fps=None, **_):
    """ElliMann's JSON: the mannequin (recording how its skin was made), with its pose section when posed."""
    mannequin = with_skin_record(mannequin, skin)
    for path in paths:
        if frames is None:
            mannequin.save(path)
        else:
            data = mannequin.to_dict()
            data["pose"] = pose_section(frames, fps)
            atomic_write_text(path, json.dumps(data, indent=1) + "\n")
    return paths


def write_obj_files(mannequin, paths, *, cushions=False, skin=None, frames=None, **_):
    """OBJ (Y up): the pieces (cushion pairs as their hull meshes with ``cushions``), or the skin alone; posed, a
    still pose only (an OBJ holds no animation)."""
    if frames is not None and len(frames) > 1:
        raise ElliMannError(
            f"pose: a .obj file holds no animation; write the {len(frames)} frames of "
            f"'{frames[0].name.rsplit(' ', 1)[0]}' to .json or .xml (keyframes), or pose a still pose"
        )
    pose = frames[0] if frames else None
    for path in paths:
        if skin is not None:
            write_skin_obj(skin, path, pose)
        else:
            write_obj(mannequin, path, pose, cushions)
    return paths


def write_mjcf_files(mannequin, paths, *, cushions=False, skin=None, frames=None, **_):
    """MJCF: the convex pieces welded to the world (cushion pairs as convex mesh geoms with ``cushions``), the skin
    drawn over them; posed, an articulated body with the frames as keyframes."""
    mannequin = with_skin_record(mannequin, skin)
    for path in paths:
        if frames is None:
            write_mjcf(mannequin, path, cushions=cushions, skin=skin)
        else:
            from .mjcf_articulated import write_articulated_mjcf

            write_articulated_mjcf(mannequin, path, frames, cushions, skin)
    return paths


def with_skin_record(mannequin, skin):
    """``mannequin`` recording how ``skin`` was made (its file's ``skin`` section); ElliMannError if the skin was
    made from other pieces (a caller's mistake: the file would hold a skin its pieces do not make)."""
    if skin is None:
        return mannequin
    made_from = skin.mannequin
    if made_from is not mannequin and not all(
        np.array_equal(getattr(made_from, field), getattr(mannequin, field))
        for field in ("rotation", "center", "semi_axes")
    ):
        raise ElliMannError(f"skin: made from other pieces than those of '{mannequin.name}'")
    return mannequin.copy(skin=skin.record())
