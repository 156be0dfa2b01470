"""A .glb's JSON chunk and ElliMann's extras in it, read with the standard library (no Blender): what ``measure``
reads of a .glb, and what the Blender layer's exporter writes (``blender.services.files``, which takes the keys from
here). Layout: docs/formats/gltf_extras.md.

Only the 12-byte header and the JSON chunk are read (the binary chunk, the meshes, is not), and a JSON chunk larger
than ``core.files.MAX_READ_BYTES`` is refused before it is read."""

import json
import os
import struct

from ..errors import ElliMannError
from ..files import MAX_READ_BYTES

EXTRAS_KEY = "ellimann"
EXTRAS_FORMAT = "ellimann.gltf-extras"
EXTRAS_VERSION = 1


def read_glb_json(path):
    """The JSON chunk of a binary glTF file as a dict; ElliMannError naming the file if it is not a whole .glb (its
    header's length is the file's, its first chunk is JSON and fits) or its JSON chunk is over MAX_READ_BYTES."""
    with open(path, "rb") as stream:
        size = os.fstat(stream.fileno()).st_size
        head = stream.read(20)
        if len(head) < 20:
            raise ElliMannError(f"path: {path} is not a binary glTF file (it is {size} bytes)")
        magic, _, total = struct.unpack_from("<4sII", head)
        length, kind = struct.unpack_from("<I4s", head, 12)
        if magic != b"glTF" or kind != b"JSON":
            raise ElliMannError(f"path: {path} is not a binary glTF file (no glTF header and JSON chunk)")
        if total != size or 20 + length > size:
            raise ElliMannError(f"path: {path} is not a whole binary glTF file ({size} bytes, its header says {total})")
        if length > MAX_READ_BYTES:
            raise ElliMannError(
                f"path: {path}'s JSON chunk is {length / 1000**2:,.1f} MB; at most {MAX_READ_BYTES / 1000**2:g} MB "
                "is read (refused before reading it)"
            )
        chunk = stream.read(length)
    try:
        return json.loads(chunk)
    except (UnicodeDecodeError, ValueError, RecursionError) as error:
        raise ElliMannError(f"path: {path}'s JSON chunk is not valid JSON ({' '.join(str(error).split())})") from None


def scene_extras(doc, path):
    """ElliMann's extras of the first scene of a .glb's JSON (``read_glb_json``): {format, version, name, role,
    measured_cm, target_cm, ...}; ElliMannError naming the file if it has none or of another format or version."""
    scenes = doc.get("scenes") if isinstance(doc, dict) else None
    first = scenes[0] if isinstance(scenes, list) and scenes and isinstance(scenes[0], dict) else {}
    extras = first.get("extras")
    extras = extras.get(EXTRAS_KEY) if isinstance(extras, dict) else None
    if not isinstance(extras, dict):
        raise ElliMannError(f"path: {path} holds no ElliMann extras (scenes[0].extras.{EXTRAS_KEY}): not ElliMann's")
    if extras.get("format") != EXTRAS_FORMAT or extras.get("version") != EXTRAS_VERSION:
        raise ElliMannError(
            f"path: {path}'s extras are {extras.get('format')!r} version {extras.get('version')!r}; this ElliMann "
            f"reads {EXTRAS_FORMAT!r} version {EXTRAS_VERSION}"
        )
    return extras


def skin_nodes(doc):
    """The ``skin`` records (how each skin was made: voxel_mm, blend, ...) of the nodes whose extras say kind SKIN."""
    nodes = doc.get("nodes") if isinstance(doc, dict) else None
    out = []
    for node in nodes if isinstance(nodes, list) else []:
        extras = node.get("extras") if isinstance(node, dict) else None
        extras = extras.get(EXTRAS_KEY) if isinstance(extras, dict) else None
        if isinstance(extras, dict) and extras.get("kind") == "SKIN":
            out.append(extras.get("skin") if isinstance(extras.get("skin"), dict) else {})
    return out
