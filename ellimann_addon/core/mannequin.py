"""Mannequins: a topology (named parts and their rules) plus geometry arrays, with validation and JSON.

Topology (paper, Section 2.3.2) is data: each part is an ellipsoid with a name in the paper's style
(``10.a Trapezius.L``), a side, a body region, whether it takes part in the girth sections, the
measurements it depends on (segmented IDW) and an optional cushion partner (same number, other
letter, same side). Geometry is three arrays in topology order: rotation (n, 3, 3), center (n, 3)
and semi_axes (n, 3), in metres.
"""

import json
import re
from dataclasses import dataclass, field

import numpy as np

from .constants import CENTER_LIMIT, FEMALE_SET, MEASUREMENTS, SECTION_FRACTIONS, SEMI_AXIS_LIMITS
from .errors import MannequinError, Problem
from .files import atomic_write_text
from .joints import joint_problems, joints_from_dict, joints_to_dict
from .problems import json_type as _json_type
from .problems import measurement_problems, section_fraction_problems
from .problems import short as _short
from .trace import traces_from_dict, traces_to_dict

FORMAT = "ellimann.mannequin"
FORMAT_VERSION = 2  # 2: "measured_with" (the reference set and section heights); a version 1 file is female
SIDES = ("L", "R", "C")
ROLES = ("base", "reference", "synthesized")
NAME_PATTERN = re.compile(r"^(?P<number>\d+)\.(?P<letter>[a-z]) (?P<label>[^.]+?)(?:\.(?P<side>[LR]))?$")
ROTATION_TOL = 1e-6


def twin_name(name):
    """'7.a Thigh.L' -> '7.a Thigh.R' and back; central names are their own twin."""
    if name.endswith(".L"):
        return name[:-2] + ".R"
    if name.endswith(".R"):
        return name[:-2] + ".L"
    return name


def side_of_name(name):
    return name[-1] if name.endswith((".L", ".R")) else "C"


@dataclass(frozen=True)
class Part:
    """One ellipsoid of a topology. ``partner`` is the other ellipsoid of its cushion, or ''."""

    name: str
    side: str
    region: str
    girth: bool
    depends: tuple
    partner: str = ""

    def to_dict(self):
        return {"name": self.name, "side": self.side, "region": self.region, "girth": self.girth,
                "depends": list(self.depends), "partner": self.partner}

    @classmethod
    def from_dict(cls, data):
        problems = []
        name = data.get("name") if isinstance(data, dict) else None
        if not isinstance(name, str) or not name:
            raise MannequinError([Problem("", "name", "every ellipsoid needs a non-empty name")])
        for key, kind in (("side", str), ("region", str), ("girth", bool), ("depends", list)):
            if not isinstance(data.get(key), kind):
                problems.append(Problem(name, key, f"missing or not a {kind.__name__}"))
        depends = data.get("depends")
        if isinstance(depends, list) and not all(isinstance(m, str) for m in depends):
            problems.append(Problem(name, "depends", f"must list measurement names among {', '.join(MEASUREMENTS)}, "
                                                     f"got {_short(depends)}"))
        partner = data.get("partner") or ""
        if not isinstance(partner, str):
            problems.append(Problem(name, "partner", "must be a name or empty"))
        if problems:
            raise MannequinError(problems)
        return cls(name, data["side"], data["region"], data["girth"], tuple(data["depends"]), partner)


class Topology:
    """An ordered, validated tuple of parts with lookups for twins, cushions and masks."""

    def __init__(self, parts):
        self.parts = tuple(parts)
        problems = self.problems()
        if problems:
            raise MannequinError(problems)
        self.names = tuple(p.name for p in self.parts)
        self.index = {name: i for i, name in enumerate(self.names)}
        # The masks, built once (synthesis asks for them on every call); the properties hand out copies.
        self._girth = np.array([p.girth for p in self.parts], dtype=bool)
        self._depends = np.array([[m in p.depends for m in MEASUREMENTS] for p in self.parts], dtype=bool)

    def __len__(self):
        return len(self.parts)

    def __iter__(self):
        return iter(self.parts)

    def __eq__(self, other):
        return isinstance(other, Topology) and self.parts == other.parts

    def __hash__(self):
        return hash(self.parts)

    def problems(self):
        """Every inconsistency of the topology, each naming the ellipsoid and field."""
        out = []
        seen = {}
        for part in self.parts:
            if part.name in seen:
                out.append(Problem(part.name, "name", "is used twice"))
            seen[part.name] = part
        for part in self.parts:
            name = part.name
            match = NAME_PATTERN.match(name)
            if not match:
                out.append(Problem(name, "name", "must look like '10.a Trapezius.L' (number.letter label[.L|.R])"))
            if part.side not in SIDES:
                out.append(Problem(name, "side", f"is '{part.side}'; expected one of L, R, C"))
            elif side_of_name(name) != part.side:
                out.append(Problem(name, "side", f"is '{part.side}' but the name's suffix says "
                                                 f"'{side_of_name(name)}'"))
            unknown = [m for m in part.depends if m not in MEASUREMENTS]
            if unknown or not part.depends:
                out.append(Problem(name, "depends", f"must be a non-empty subset of {', '.join(MEASUREMENTS)}"
                                                    + (f"; unknown {unknown}" if unknown else "")))
            elif len(set(part.depends)) != len(part.depends):
                out.append(Problem(name, "depends", "lists a measurement twice"))
            if part.side in ("L", "R"):
                twin = seen.get(twin_name(name))
                if twin is None:
                    out.append(Problem(name, "side", f"has no mirror twin '{twin_name(name)}'"))
                elif (twin.region, twin.girth, tuple(sorted(twin.depends))) != (
                        part.region, part.girth, tuple(sorted(part.depends))):
                    out.append(Problem(name, "twin", f"region, girth flag or depends differ from '{twin.name}'"))
                elif twin_name(part.partner) != twin.partner:
                    out.append(Problem(name, "partner", f"cushion partner does not mirror that of '{twin.name}'"))
            if part.partner:
                other = seen.get(part.partner)
                if other is None:
                    out.append(Problem(name, "partner", f"cushion partner '{part.partner}' does not exist"))
                elif other.partner != name:
                    out.append(Problem(name, "partner", f"'{part.partner}' does not name it back as partner"))
                elif other.side != part.side:
                    out.append(Problem(name, "partner", f"'{part.partner}' is on another side"))
                elif other is part:
                    out.append(Problem(name, "partner", "cannot be its own partner"))
        return out

    @property
    def girth_mask(self):
        return self._girth.copy()

    @property
    def dependency_mask(self):
        """(n, 5) bool: which measurements each ellipsoid depends on, in MEASUREMENTS order."""
        return self._depends.copy()

    @property
    def twin_indices(self):
        """For each part, the index of its mirror twin (itself if central)."""
        return np.array([self.index[twin_name(n)] for n in self.names])

    def indices(self, side):
        return np.array([i for i, p in enumerate(self.parts) if p.side == side], dtype=int)

    @property
    def cushion_pairs(self):
        """(first, second) index pairs; the first is the part whose letter sorts first (the 'a')."""
        pairs = []
        for i, part in enumerate(self.parts):
            if part.partner:
                j = self.index[part.partner]
                if _letter(part.name) < _letter(part.partner):
                    pairs.append((i, j))
        return pairs

    def single_parts(self, cushions=True):
        """Indices of the parts that are pieces of the body on their own: with ``cushions`` those in
        no cushion pair (the pairs become cushions), else all of them."""
        paired = {i for pair in self.cushion_pairs for i in pair} if cushions else set()
        return [i for i in range(len(self.parts)) if i not in paired]

    @classmethod
    def from_list(cls, items):
        parts, problems = [], []
        for item in items:
            try:
                parts.append(Part.from_dict(item))
            except MannequinError as error:
                problems.extend(error.problems)
        if problems:
            raise MannequinError(problems)
        return cls(parts)

    def mismatch(self, other):
        """Problems that keep two mannequins from being interpolated or compared part by part."""
        out = []
        mine, theirs = set(self.names), set(other.names)
        out += [Problem(n, "topology", "is missing from the other mannequin") for n in self.names if n not in theirs]
        out += [Problem(n, "topology", "is not in this mannequin") for n in other.names if n not in mine]
        if not out:
            for part in self.parts:
                if part != other.parts[other.index[part.name]]:
                    out.append(Problem(part.name, "topology", "has different side, region, girth, depends or "
                                                              "partner in the other mannequin"))
        return out


def _letter(name):
    match = NAME_PATTERN.match(name)
    return match.group("letter") if match else name


@dataclass
class Mannequin:
    """A topology with geometry. ``measurements`` are the requested/target tailor measurements in cm.

    ``reference_set`` and ``section_fractions``: the reference set the mannequin belongs to (synthesized from,
    or part of) and the section heights m_T measures it at (fractions of He); the female set's by default.
    ``joints``: None or the (24, 3) rest joint centres in SMPL order (core.skeleton, core.joints).
    """

    topology: Topology
    rotation: np.ndarray
    center: np.ndarray
    semi_axes: np.ndarray
    name: str = ""
    role: str = "synthesized"
    measurements: dict = field(default=None)
    traces: dict = field(default=None)  # {part name: core.trace.PartTrace}: what each part was traced from
    reference_set: str = FEMALE_SET
    section_fractions: dict = field(default=None)
    joints: np.ndarray = None

    def __post_init__(self):
        # a copy (mannequins never share one); anything but a dict is left for problems() to name
        fractions = SECTION_FRACTIONS if self.section_fractions is None else self.section_fractions
        self.section_fractions = dict(fractions) if isinstance(fractions, dict) else fractions
        self.rotation = np.asarray(self.rotation, dtype=float)
        self.center = np.asarray(self.center, dtype=float)
        self.semi_axes = np.asarray(self.semi_axes, dtype=float)
        self.joints = None if self.joints is None else np.asarray(self.joints, dtype=float)

    def __len__(self):
        return len(self.topology)

    def copy(self, **changes):
        values = dict(topology=self.topology, rotation=self.rotation.copy(), center=self.center.copy(),
                      semi_axes=self.semi_axes.copy(), name=self.name, role=self.role,
                      measurements=dict(self.measurements) if self.measurements else None,
                      traces=dict(self.traces) if self.traces else None,
                      reference_set=self.reference_set, section_fractions=self.section_fractions,
                      joints=None if self.joints is None else self.joints.copy())
        values.update(changes)
        return Mannequin(**values)

    def translated(self, offset):
        """The mannequin moved by ``offset`` (3,) m, its joints with it."""
        offset = np.asarray(offset, dtype=float)
        return self.copy(center=self.center + offset, joints=None if self.joints is None else self.joints + offset)

    def problems(self):
        """Geometry problems, each naming the ellipsoid and field (the topology validated itself)."""
        n = len(self.topology)
        out = []
        for attr, shape in (("rotation", (n, 3, 3)), ("center", (n, 3)), ("semi_axes", (n, 3))):
            if getattr(self, attr).shape != shape:
                out.append(Problem("", attr, f"has shape {getattr(self, attr).shape}; expected {shape}"))
        if out:
            return out
        if self.role not in ROLES:
            out.append(Problem("", "role", f"is '{self.role}'; expected one of {', '.join(ROLES)}"))
        with np.errstate(invalid="ignore", over="ignore"):  # a non-finite or huge frame is reported below
            det = np.linalg.det(self.rotation)
            gram = np.swapaxes(self.rotation, -1, -2) @ self.rotation
            ortho_error = np.abs(gram - np.eye(3)).max(axis=(1, 2))
        low, high = SEMI_AXIS_LIMITS
        with np.errstate(invalid="ignore"):
            implausible_axes = np.any((self.semi_axes < low) | (self.semi_axes > high), axis=1)
            far = np.any(np.abs(self.center) > CENTER_LIMIT, axis=1)
        for i, part in enumerate(self.topology):
            finite = {}
            for attr in ("rotation", "center", "semi_axes"):
                finite[attr] = bool(np.all(np.isfinite(getattr(self, attr)[i])))
                if not finite[attr]:
                    out.append(Problem(part.name, attr, "contains NaN or infinity"))
            if np.any(self.semi_axes[i] <= 0.0):
                out.append(Problem(part.name, "semi_axes", f"must be > 0, got {self.semi_axes[i].tolist()}"))
            elif finite["semi_axes"] and implausible_axes[i]:
                value = next(v for v in self.semi_axes[i] if not low <= v <= high)
                out.append(Problem(part.name, "semi_axes", f"{value:g} m is not a plausible semi-axis (accepted range "
                                                           f"{low:g} to {high:g} m)"))
            if finite["center"] and far[i]:
                axis = int(np.argmax(np.abs(self.center[i])))
                out.append(Problem(part.name, "center", f"{'xyz'[axis]} = {self.center[i, axis]:g} m is too far from "
                                                        f"the origin (accepted range {-CENTER_LIMIT:g} to "
                                                        f"{CENTER_LIMIT:g} m)"))
            if np.all(np.isfinite(self.rotation[i])):
                if ortho_error[i] > ROTATION_TOL:
                    out.append(Problem(part.name, "rotation", f"is not orthonormal (error {ortho_error[i]:.2g})"))
                elif det[i] < 0.0:
                    out.append(Problem(part.name, "rotation", "is a left-handed frame (det -1)"))
        out += measurement_problems(self.measurements)
        if not isinstance(self.reference_set, str) or not self.reference_set:
            out.append(Problem("", "reference_set", f"must be a non-empty name, got {_short(self.reference_set)}"))
        out += section_fraction_problems(self.section_fractions)
        return out + joint_problems(self)

    def check(self):
        """Raise MannequinError listing every problem; return self when valid."""
        problems = self.problems()
        if problems:
            raise MannequinError(problems)
        return self

    def measure(self):
        """m_T in cm as a dict (closed form)."""
        from .measure import as_dict, tailor_measurements

        return as_dict(tailor_measurements(self.rotation, self.center, self.semi_axes, self.topology.girth_mask,
                                           self.section_fractions))

    def reordered(self, topology):
        """The same mannequin with its parts in ``topology``'s order (which must have the same parts)."""
        problems = self.topology.mismatch(topology)
        if problems:
            raise MannequinError(problems)
        order = np.array([self.topology.index[n] for n in topology.names])
        return self.copy(topology=topology, rotation=self.rotation[order], center=self.center[order],
                         semi_axes=self.semi_axes[order])

    def to_dict(self):
        traces = {"traces": traces_to_dict(self.traces)} if self.traces else {}
        joints = {} if self.joints is None else {"joints": joints_to_dict(self.joints)}
        return {
            "format": FORMAT,
            "version": FORMAT_VERSION,
            "name": self.name,
            "role": self.role,
            "units": "m",
            "measurements_cm": self.measurements,
            "measured_with": {"reference_set": self.reference_set, "section_fractions": self.section_fractions},
            "ellipsoids": [
                dict(part.to_dict(), center=self.center[i].tolist(),
                     axes=self.rotation[i].T.tolist(), semi_axes=self.semi_axes[i].tolist())
                for i, part in enumerate(self.topology)
            ],
            **traces,
            **joints,
        }

    @classmethod
    def from_dict(cls, data, check=True):
        """A mannequin from its JSON dict; MannequinError names every field that is missing, of the wrong
        type or implausible (never another exception, whatever ``data`` holds)."""
        if not isinstance(data, dict):
            raise MannequinError([Problem("", "file", f"holds {_json_type(data)}, not an ElliMann mannequin "
                                                      f"(an object with format '{FORMAT}')")])
        if data.get("format") != FORMAT:
            raise MannequinError([Problem("", "format", f"not an ElliMann mannequin (expected format '{FORMAT}')")])
        version = data.get("version")
        if isinstance(version, bool) or not isinstance(version, int) or not 1 <= version <= FORMAT_VERSION:
            raise MannequinError([Problem("", "version", f"is {_short(version)}; this ElliMann reads versions 1 to "
                                                         f"{FORMAT_VERSION}")])
        problems = []
        units = data.get("units", "m")
        if units != "m":
            problems.append(Problem("", "units", f"is {_short(units)}; mannequin files are in metres ('m')"))
        name, role = (data.get("name") or "", data.get("role") or "synthesized")  # null as if absent
        for key, value, kinds in (("name", name, "a string"), ("role", role, f"one of {', '.join(ROLES)}")):
            if not isinstance(value, str):
                problems.append(Problem("", key, f"must be {kinds}, got {_json_type(value)}"))
        measurements = data.get("measurements_cm")
        if measurements is not None and not isinstance(measurements, dict):
            problems.append(Problem("", "measurements_cm", "must be an object of He, Sh, Br, Wa, Hi in cm (or null), "
                                                           f"got {_json_type(measurements)}"))
        measured_with = data.get("measured_with") or {}  # absent (version 1): the female set
        if not isinstance(measured_with, dict):
            problems.append(Problem("", "measured_with", "must be an object (reference_set, section_fractions), got "
                                                         f"{_json_type(measured_with)}"))
            measured_with = {}
        landmarks = {"reference_set": measured_with.get("reference_set", FEMALE_SET),
                     "section_fractions": measured_with.get("section_fractions", SECTION_FRACTIONS)}
        if not isinstance(landmarks["section_fractions"], dict):
            problems.append(Problem("", "measured_with.section_fractions", "must be an object of Sh, Br, Wa, Hi, got "
                                                                           f"{_json_type(landmarks['section_fractions'])}"))
        items = data.get("ellipsoids")
        if not isinstance(items, list) or not items:
            got = "it is missing" if items is None else "it is empty" if items == [] else f"got {_json_type(items)}"
            problems.append(Problem("", "ellipsoids", f"must be a non-empty list of ellipsoid objects; {got}"))
        else:
            problems += [Problem("", f"ellipsoids[{i}]", f"must be an object (name, side, region, girth, depends, "
                                                         f"center, axes, semi_axes), got {_json_type(item)}")
                         for i, item in enumerate(items) if not isinstance(item, dict)]
        if problems:
            raise MannequinError(problems)
        topology = Topology.from_list(items)
        problems = []
        arrays = {"center": [], "axes": [], "semi_axes": []}
        for item in items:
            for key, shape in (("center", (3,)), ("axes", (3, 3)), ("semi_axes", (3,))):
                try:
                    value = np.array(item.get(key), dtype=float)
                except (TypeError, ValueError, OverflowError, RecursionError):
                    value = None
                if value is None or value.shape != shape:
                    problems.append(Problem(item["name"], key, f"missing or not a {'x'.join(map(str, shape))} array"))
                    value = np.full(shape, np.nan)
                arrays[key].append(value)
        if problems:
            raise MannequinError(problems)
        mannequin = cls(topology, np.swapaxes(np.array(arrays["axes"]), 1, 2), np.array(arrays["center"]),
                        np.array(arrays["semi_axes"]), name=name, role=role, measurements=measurements,
                        traces=traces_from_dict(data.get("traces"), topology.names),
                        joints=joints_from_dict(data.get("joints")), **landmarks)
        return mannequin.check() if check else mannequin

    def to_json(self):
        return json.dumps(self.to_dict(), indent=1)

    def save(self, path):
        atomic_write_text(path, self.to_json() + "\n")

    @classmethod
    def load(cls, path, check=True):
        """Read a mannequin JSON file (UTF-8). Whatever the file holds, a bad one raises MannequinError naming
        the file or the field (OSError if it cannot be opened)."""
        with open(path, "rb") as stream:
            raw = stream.read()
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as error:
            encoding = _bom_encoding(raw)
            what = f"is {encoding} text" if encoding else f"is not UTF-8 text (byte {error.start} is " \
                                                          f"{raw[error.start]:#04x})"
            raise MannequinError([Problem("", "file", f"{path} {what}; mannequin files are JSON in UTF-8")]) from None
        try:
            data = json.loads(text)
        except RecursionError:
            raise MannequinError([Problem("", "file", f"{path} is nested too deeply to be a mannequin (its "
                                                      "JSON is 4 levels deep)")]) from None
        except ValueError as error:  # JSONDecodeError, or an integer too long to convert
            raise MannequinError([Problem("", "file", f"{path} is not valid JSON ({error})")]) from None
        return cls.from_dict(data, check=check)


def _bom_encoding(raw):
    """'UTF-16' or 'UTF-32' if ``raw`` starts with that byte-order mark or looks like that encoding, else ''."""
    if raw[:4] in (b"\xff\xfe\x00\x00", b"\x00\x00\xfe\xff"):
        return "UTF-32"
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff") or (len(raw) >= 2 and b"\x00" in raw[:2]):
        return "UTF-16"
    return ""


def stack(mannequins):
    """Batch arrays (B, n, ...) of mannequins sharing one topology (reordered to the first's)."""
    topology = mannequins[0].topology
    items = [m if m.topology == topology else m.reordered(topology) for m in mannequins]
    return (np.stack([m.rotation for m in items]), np.stack([m.center for m in items]),
            np.stack([m.semi_axes for m in items]))
