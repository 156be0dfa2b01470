"""Posed mannequin files (``--pose``), as the core's writers write them (``core.formats.core_writers``): .json, MJCF
.xml and .obj; the pose section of a .json, and reading a pose file.

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
from ..files import TooLargeError, read_bytes_within
from ..pose.kinematics import Pose

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
