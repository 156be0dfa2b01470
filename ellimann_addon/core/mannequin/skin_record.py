"""How a mannequin's skin is made, and how its file records it.

Two kinds of skin: the **body** skin (``core.body``: the reference set's own bodies interpolated for the request and
corrected on the mesh until it measures it; the default wherever a set has bodies) and the smooth skin over the
**pieces** (``core.skin``: their field meshed at a voxel, neighbours blended; any set). :class:`SkinSettings` says
which and, for the pieces' skin, its voxel and blend; a file's versioned ``skin`` section records it so that the skin
can be made again (``ellimann pose IN.json --skin``), checked on load like the other sections: version 1 is the
pieces' skin {voxel_mm, blend, method}, version 2 the body skin {kind, method, request: the measurements it was made
to meet}.

A record is a recipe, not a result: it stays true whatever is done to the pieces (the same pieces give the same
pieces' skin, bit for bit; the same set and request the same body skin), so it records no measurement.
"""

import math
from dataclasses import dataclass, replace

from ..errors import ElliMannError, MannequinError, Problem
from ..measurements import ALL_MEASUREMENTS
from ..settings import BLEND_RANGE, DEFAULT_BLEND, LEVELS, VOXEL_RANGE_MM
from .field_checks import json_type, short

SKIN_VERSION = 1  # of the ``skin`` section of the pieces' skin
BODY_SKIN_VERSION = 2  # of the body skin's
KINDS = ("auto", "body", "pieces")  # auto: the body skin where the set has bodies, else the pieces'
FIELDS = ("version", "voxel_mm", "blend", "method")
BODY_FIELDS = ("version", "kind", "method", "request")
METHOD = (
    "signed-distance bound of each ellipsoid; neighbours in the body blended by the polynomial smooth minimum "
    "(width: blend times the thinner piece's smallest semi-axis, at most 4 cm), the blends joined by a 4-norm; "
    "pieces that do not touch, one off the trunk, kept 1.25 voxels apart unless that leaves more handles or "
    "parts the body; "
    "marching cubes with a watertight table"
)
BODY_METHOD = (
    "the reference set's bodies (one topology) interpolated for the request by its body model, then deformed "
    "smoothly until the body-mesh measurer reads the request (core.body)"
)


@dataclass(frozen=True)
class SkinSettings:
    """A skin's ``kind`` ("body", "pieces" or "auto": the body skin where the set has bodies, else the pieces') and,
    for the pieces' skin, its voxel (mm) and blend (times the thinner piece's smallest semi-axis)."""

    voxel_mm: float = LEVELS["final"]
    blend: float = DEFAULT_BLEND
    kind: str = "pieces"

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ElliMannError(f"skin_kind: must be one of {', '.join(KINDS)}, got {self.kind!r}")
        for name, value, (low, high) in (
            ("skin_voxel", self.voxel_mm, VOXEL_RANGE_MM),
            ("skin_blend", self.blend, BLEND_RANGE),
        ):
            number = isinstance(value, (int, float)) and not isinstance(value, bool)
            if not number or not math.isfinite(value) or not low <= value <= high:
                raise ElliMannError(f"{name}: must be a number from {low:g} to {high:g}, got {value!r}")

    @classmethod
    def at_level(cls, level, voxel_mm=None, blend=DEFAULT_BLEND, kind="pieces"):
        """The settings of a level ("preview", "final"), its voxel replaced by ``voxel_mm`` if given."""
        if level not in LEVELS:
            raise ElliMannError(f"skin_level: must be one of {', '.join(LEVELS)}, got {level!r}")
        return cls(LEVELS[level] if voxel_mm is None else voxel_mm, blend, kind)

    @property
    def voxel(self):
        """The voxel in metres."""
        return self.voxel_mm / 1000.0

    def of_kind(self, kind):
        return replace(self, kind=kind)

    def describe(self):
        """ "body skin", "skin 5 mm" (and its blend when it is not the default)."""
        if self.kind == "body":
            return "body skin"
        blend = "" if self.blend == DEFAULT_BLEND else f", blend {self.blend:g}"
        return f"skin {self.voxel_mm:g} mm{blend}"

    def to_dict(self, request=None):
        """The ``skin`` section of a mannequin file: how its skin was made, so that it can be made again (a body
        skin: with the ``request`` it was made to meet, {key: cm})."""
        if self.kind == "body":
            return {
                "version": BODY_SKIN_VERSION,
                "kind": "body",
                "method": BODY_METHOD,
                "request": {key: float(value) for key, value in (request or {}).items()},
            }
        return {"version": SKIN_VERSION, "voxel_mm": self.voxel_mm, "blend": self.blend, "method": METHOD}

    @classmethod
    def from_dict(cls, data):
        """The settings a ``skin`` section records (checked: :func:`skin_record_problems`)."""
        problems = skin_record_problems(data)
        if problems:
            raise ElliMannError(str(MannequinError(problems)))
        if data["version"] == BODY_SKIN_VERSION:
            return cls(kind="body")
        return cls(float(data["voxel_mm"]), float(data["blend"]))


def skin_record_problems(data):
    """Problems of a ``skin`` section: an object of version SKIN_VERSION with voxel_mm and blend (numbers within their
    ranges) and method (a string, what the skin was made by), or of BODY_SKIN_VERSION with kind "body", method and
    request (the measurements it was made to meet, {key: cm})."""

    def problem(field, message):
        return [Problem("", f"skin.{field}" if field else "skin", message)]

    if not isinstance(data, dict):
        return problem("", f"must be an object ({', '.join(FIELDS)}) or absent, got {json_type(data)}")
    version = data.get("version")
    if isinstance(version, bool) or version not in (SKIN_VERSION, BODY_SKIN_VERSION):
        return problem(
            "version", f"is {short(version)}; this ElliMann reads skin versions {SKIN_VERSION} and {BODY_SKIN_VERSION}"
        )
    out = []
    if version == BODY_SKIN_VERSION:
        if data.get("kind") != "body":
            out += problem("kind", f'must be "body" in version {BODY_SKIN_VERSION}, got {short(data.get("kind"))}')
        request = data.get("request")
        if not isinstance(request, dict) or any(
            key not in ALL_MEASUREMENTS or isinstance(value, bool) or not isinstance(value, (int, float))
            for key, value in request.items()
        ):
            out += problem("request", f"must be an object of measurements ({', '.join(ALL_MEASUREMENTS)}) in cm")
        fields = BODY_FIELDS
    else:
        for field, (low, high) in (("voxel_mm", VOXEL_RANGE_MM), ("blend", BLEND_RANGE)):
            value = data.get(field)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                out += problem(field, f"must be a number from {low:g} to {high:g}, got {short(value)}")
            elif not low <= value <= high:
                out += problem(field, f"is {value:g}; accepted range {low:g} to {high:g}")
        fields = FIELDS
    if not isinstance(data.get("method"), str):
        out += problem("method", f"must be a string (how the skin was made), got {json_type(data.get('method'))}")
    unknown = [key for key in data if key not in fields]
    if unknown:
        out += problem(short(unknown[0]), f"is not a field of the skin section ({', '.join(fields)})")
    return out


def skin_record_from_dict(data):
    """The ``skin`` section of a mannequin file (None if absent) as a plain dict of its fields; MannequinError naming
    the field otherwise."""
    if data is None:
        return None
    problems = skin_record_problems(data)
    if problems:
        raise MannequinError(problems)
    if data["version"] == BODY_SKIN_VERSION:
        return {**{key: data[key] for key in BODY_FIELDS}, "request": dict(data["request"])}
    return {key: float(data[key]) if key in ("voxel_mm", "blend") else data[key] for key in FIELDS}
