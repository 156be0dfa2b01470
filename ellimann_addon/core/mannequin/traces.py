"""What a part was traced from: the vertices of which mesh it was fitted to, and the fit's settings.

Fit Ellipsoid records it on the part; the Base Mannequin carries it (JSON: the mannequin's ``traces``
section, versioned on its own; .blend: the part's properties), and the reference-set builder
(core/fitting/reference_build.py) fits every part to the same vertices on each body of the traced mesh's
topology. Vertex lists are written as runs (``"0-15 20 22-40"``): a part selects hundreds to thousands
of mostly consecutive vertices.
"""

from dataclasses import asdict, dataclass, field, fields

import numpy as np

from ..errors import MannequinError, Problem

TRACES_VERSION = 1
FRAMES = ("limb", "main", "axis", "fixed")
METHODS = ("inscribed", "moments", "enclosing")  # Fit Ellipsoid's sizes (features/trace)


@dataclass(frozen=True)
class FitSettings:
    """How the builder fits a part inside each body (core/fitting/inscribed.py's ``inscribed_ellipsoid``)."""

    margin: float = 0.3  # box enlargement, fraction of the selection's half-extent
    depth: float = 0.005  # m: how far the part may reach outside the body surface (or a mitten's hull)
    inside: float = 0.003  # share of the nearby body surface (by area) that may lie inside it anyway
    span: bool = False  # the part reaches from one end of its selection to the other along its axis
    inward: tuple = None  # extrude the selected surface patch by this vector (m) into the body before fitting
    frame: str = "main"  # the axis the frame takes from the points: "limb", "main", "axis" (``axis``) or "fixed"
    mitten: bool = False  # kept inside the convex hull of its own vertices instead of the body surface
    level: str = None  # a section (Br, Wa, ...) the part is centred on
    axis: tuple = None  # world direction of a limb, when its longest extent is not along it (a short neck)
    clear: tuple = ()  # sections it keeps clear of, besides those of the measurements it does not follow
    kept: int = None  # the column of the base part's frame taken from the points (None: none was)
    # None: the fit's own (core.fitting.mannequin_fit.FitConstants); a topology may set its own per part
    clearance: float = None  # fraction of the height kept clear of the sections of measurements it does not follow
    shared: float = None  # what volume another part covers too is worth to it, after the first pass (0 to 1)
    # m: besides the body's vertices, it keeps clear of points this far apart on the triangles with longer edges
    # (core.fitting.body_mesh.surface_walls); None: of the vertices only
    wall_spacing: float = None
    # what covering a cell outside the body costs the part when it is placed, in cells inside that no other part
    # fills (core.fitting.mannequin_fit); None: nothing, it is placed for the inside it fills alone
    outside_cost: float = None

    # written only when set: traces made before them read the same
    _DEFAULTED = ("clearance", "shared", "wall_spacing", "outside_cost")

    def to_dict(self):
        out = asdict(self)
        for key in self._DEFAULTED:
            if out[key] is None:
                del out[key]
        for key in ("inward", "axis", "clear"):
            out[key] = None if out[key] is None else list(out[key])
        return out

    @classmethod
    def from_dict(cls, data, part):
        if not isinstance(data, dict):
            raise MannequinError([Problem(part, "traces.fit", "must be an object")])
        known = {f.name: f for f in fields(cls)}
        values = {}
        for key, value in data.items():
            if key not in known:
                raise MannequinError(
                    [Problem(part, f"traces.fit.{key}", f"is not a fit setting; expected some of {', '.join(known)}")]
                )
            values[key] = _fit_value(part, key, value)
        return cls(**values)


_LIMITS = {"clearance": (0.0, 0.2), "shared": (0.0, 1.0), "wall_spacing": (0.001, 0.1), "outside_cost": (0.0, 10.0)}


def _fit_value(part, key, value):
    def bad(expected):
        return MannequinError([Problem(part, f"traces.fit.{key}", f"must be {expected}, got {value!r:.40}")])

    if key in ("margin", "depth", "inside"):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= 10.0:
            raise bad("a number from 0 to 10")
        return float(value)
    if key in _LIMITS:
        low, high = _LIMITS[key]
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not low <= value <= high:
            raise bad(f"null or a number from {low:g} to {high:g}")
        return float(value)
    if key in ("span", "mitten"):
        if not isinstance(value, bool):
            raise bad("true or false")
        return value
    if key in ("inward", "axis"):
        if value is None:
            return None
        if not (
            isinstance(value, list)
            and len(value) == 3
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) and abs(v) <= 10.0 for v in value)
        ):
            raise bad("null or 3 numbers (m)")
        return tuple(float(v) for v in value)
    if key == "frame":
        if value not in FRAMES:
            raise bad(f"one of {', '.join(FRAMES)}")
        return value
    if key == "level":
        if value is not None and not isinstance(value, str):
            raise bad("null or a section name (Br, Wa, ...)")
        return value
    if key == "clear":
        if not (isinstance(value, list) and all(isinstance(v, str) for v in value)):
            raise bad("a list of section names")
        return tuple(value)
    if value is not None and (isinstance(value, bool) or value not in (0, 1, 2)):
        raise bad("null or 0, 1, 2")
    return value


@dataclass(frozen=True)
class PartTrace:
    """The vertices (sorted indices) of the mesh ``mesh`` (``vertex_count`` vertices, connectivity
    fingerprint ``edges_crc``: core.fitting.body_mesh) a part was fitted to; ``cavity``: vertices that are no
    obstacle to it (the walls of the mesh's open mouth and eye sockets, which a solid head fills);
    ``method``: how Fit Ellipsoid sized it in Blender (the builder always inscribes)."""

    mesh: str
    vertex_count: int
    edges_crc: int
    vertices: np.ndarray
    fit: FitSettings = field(default_factory=FitSettings)
    cavity: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    method: str = "inscribed"

    def to_dict(self):
        return {
            "mesh": self.mesh,
            "vertex_count": self.vertex_count,
            "edges_crc": self.edges_crc,
            "method": self.method,
            "vertices": format_runs(self.vertices),
            "cavity": format_runs(self.cavity),
            "fit": self.fit.to_dict(),
        }

    @classmethod
    def from_dict(cls, data, part):
        if not isinstance(data, dict):
            raise MannequinError([Problem(part, "traces", "must be an object (mesh, vertex_count, vertices, fit)")])
        mesh, count, crc = data.get("mesh"), data.get("vertex_count"), data.get("edges_crc")
        if not isinstance(mesh, str):
            raise MannequinError([Problem(part, "traces.mesh", "must be the traced mesh's name")])
        for key, value in (("vertex_count", count), ("edges_crc", crc)):
            if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < 2**32:
                raise MannequinError([Problem(part, f"traces.{key}", "must be an integer from 0 to 2^32 - 1")])
        method = data.get("method", "inscribed")
        if method not in METHODS:
            raise MannequinError([Problem(part, "traces.method", f"must be one of {', '.join(METHODS)}")])
        vertices = parse_runs(data.get("vertices"), count, part, "traces.vertices")
        if not len(vertices):
            raise MannequinError([Problem(part, "traces.vertices", "lists no vertex")])
        return cls(
            mesh,
            count,
            crc,
            vertices,
            FitSettings.from_dict(data.get("fit", {}), part),
            parse_runs(data.get("cavity", ""), count, part, "traces.cavity"),
            method,
        )


def format_runs(indices):
    """'0-3 7 9-10' for [0, 1, 2, 3, 7, 9, 10] (sorted unique indices)."""
    indices = np.asarray(indices, dtype=np.int64)
    if not len(indices):
        return ""
    breaks = np.nonzero(np.diff(indices) != 1)[0]
    starts = np.concatenate([[indices[0]], indices[breaks + 1]])
    ends = np.concatenate([indices[breaks], [indices[-1]]])
    return " ".join(str(a) if a == b else f"{a}-{b}" for a, b in zip(starts.tolist(), ends.tolist()))


def parse_runs(text, count, part="", key="vertices"):
    """Sorted unique indices below ``count`` from :func:`format_runs`'s text; MannequinError if malformed."""

    def bad(why):
        return MannequinError([Problem(part, key, why)])

    if not isinstance(text, str):
        raise bad("must be a string of vertex indices and ranges ('0-15 20 22-40')")
    out = []
    for item in text.split():
        first, _, last = item.partition("-")
        if not (first.isdigit() and (not last or last.isdigit())):
            raise bad(f"'{item:.20}' is not an index or a range a-b")
        a, b = int(first), int(last or first)
        if not a <= b < count:
            raise bad(f"'{item:.20}' is not within the traced mesh's {count} vertices (0 to {count - 1})")
        out.append(np.arange(a, b + 1))
    indices = np.concatenate(out) if out else np.zeros(0, dtype=np.int64)
    if np.any(np.diff(indices) <= 0):
        raise bad("must list increasing indices")
    return indices.astype(np.int64)


def traces_to_dict(traces):
    """The JSON section of a mannequin's traces ({part name: PartTrace}); None if there are none."""
    if not traces:
        return None
    return {"version": TRACES_VERSION, "parts": {name: trace.to_dict() for name, trace in traces.items()}}


def traces_from_dict(data, names):
    """{part name: PartTrace} from a mannequin file's ``traces`` section (None: an older file, no traces)."""
    if data is None:
        return None
    if not isinstance(data, dict) or not isinstance(data.get("parts"), dict):
        raise MannequinError([Problem("", "traces", "must be an object with 'version' and 'parts'")])
    version = data.get("version")
    if isinstance(version, bool) or not isinstance(version, int) or not 1 <= version <= TRACES_VERSION:
        raise MannequinError(
            [Problem("", "traces.version", f"is {version!r:.20}; this ElliMann reads versions 1 to {TRACES_VERSION}")]
        )
    unknown = [name for name in data["parts"] if name not in names]
    if unknown:
        raise MannequinError([Problem(unknown[0], "traces", "names no ellipsoid of the mannequin")])
    return {name: PartTrace.from_dict(item, name) for name, item in data["parts"].items()}
