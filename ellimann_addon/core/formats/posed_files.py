"""Posed mannequin files the core writes without Blender (``--pose``): .json, MJCF .xml and .obj.

- ``.json``: the rest mannequin with its joints (what ``Mannequin.load`` reads, measurements the rest pose's)
  plus a ``pose`` section: ``{"version": 1, "name", "fps" (motions), "frames": [Pose.to_dict(), ...]}``; a still
  pose is one frame, the walk cycle its frames.
- ``.xml``: the articulated MJCF (``core.formats.mjcf_articulated``), the pose's frames as keyframes.
- ``.obj``: the posed pieces (``core.formats.obj``, Y up as every OBJ ElliMann writes); a still pose only (OBJ
  holds no animation).

With a skin (``--skin``): the .json records how it was made (its ``skin`` section), the .xml binds it to the
bodies, the .obj holds the posed skin alone.

:func:`read_pose` reads a pose file: such a ``.json`` (its ``pose`` section) or a bare ``Pose.to_dict``.
"""

import json

from ..errors import ElliMannError
from ..files import TooLargeError, atomic_write_text, read_bytes_within
from ..pose.kinematics import Pose
from .core_writers import with_skin_record
from .mjcf_articulated import write_articulated_mjcf
from .obj import write_obj, write_skin_obj
from .table import FORMATS, format_of

POSE_SECTION_VERSION = 1


def pose_section(frames, fps=None):
    """The JSON ``pose`` section of a list of poses (one for a still pose)."""
    section = {
        "version": POSE_SECTION_VERSION,
        "name": frames[0].name.rsplit(" ", 1)[0] if frames else "",
        "frames": [p.to_dict() for p in frames],
    }
    if fps is not None and len(frames) > 1:
        section["fps"] = fps
    return section


def read_pose(path):
    """The frames of a pose file (a posed mannequin .json, or one pose's own JSON): [Pose, ...]."""
    try:
        data = json.loads(read_bytes_within(path, what="a pose file").decode("utf-8"))
    except TooLargeError as error:
        raise ElliMannError(f"pose: {error}") from None
    except (UnicodeDecodeError, ValueError, RecursionError) as error:
        raise ElliMannError(f"pose: {path} is not a JSON pose file ({' '.join(str(error).split())})") from None
    section = data.get("pose") if isinstance(data, dict) and "pose" in data else None
    if section is None:
        return [Pose.from_dict(data)]
    if (
        not isinstance(section, dict)
        or section.get("version") != POSE_SECTION_VERSION
        or not isinstance(section.get("frames"), list)
        or not section["frames"]
    ):
        raise ElliMannError(
            f"pose: the pose section of {path} must have version {POSE_SECTION_VERSION} and a non-empty list of frames"
        )
    return [Pose.from_dict(frame) for frame in section["frames"]]


def write_posed(mannequin, frames, path, cushions=False, fps=None, skin=None):
    """Write ``mannequin`` in ``frames`` (a list of Pose; the walk cycle's frames, or one pose) to a .json, .xml
    or .obj, atomically, with its ``skin`` if given. ElliMannError (nothing written) for another format or an
    animation in a .obj."""
    kind = format_of(path)
    if kind is None or kind.posed_writer != "core":
        names = ", ".join(f".{f.extension}" for f in FORMATS.values() if f.posed_writer == "core")
        raise ElliMannError(f"path: {path!r}: the core writes posed {names} files")
    if len(frames) > 1 and not kind.animated:
        raise ElliMannError(
            f"pose: a .{kind.extension} file holds no animation; write the {len(frames)} frames "
            f"of '{frames[0].name.rsplit(' ', 1)[0]}' to .json or .xml (keyframes), or pose a still pose"
        )
    mannequin = with_skin_record(mannequin, skin)
    if kind.name == "json":
        data = mannequin.to_dict()
        data["pose"] = pose_section(frames, fps)
        atomic_write_text(path, json.dumps(data, indent=1) + "\n")
    elif kind.name == "mjcf":
        write_articulated_mjcf(mannequin, path, frames, cushions, skin)
    elif skin is not None:
        write_skin_obj(skin, path, frames[0])
    else:
        write_obj(mannequin, path, frames[0], cushions)
    return path
