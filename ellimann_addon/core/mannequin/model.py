"""Mannequins: a topology (``mannequin.topology``) plus geometry arrays, with validation and JSON.

Topology (paper, Section 2.3.2) is data: each part is an ellipsoid with a name in the paper's style
(``10.a Trapezius.L``), a side, a body region, whether it takes part in the girth sections, the
measurements it depends on (segmented IDW) and an optional cushion partner (same number, other
letter, same side). Geometry is three arrays in topology order: rotation (n, 3, 3), center (n, 3)
and semi_axes (n, 3), in metres.
"""

import json
from dataclasses import dataclass, field

import numpy as np

from ..constants import CENTER_LIMIT, FEMALE_SET, SECTION_FRACTIONS, SEMI_AXIS_LIMITS
from ..errors import MannequinError, Problem
from ..files import TooLargeError, atomic_write_text, read_bytes_within
from .field_checks import json_type as _json_type
from .field_checks import measurement_problems, section_fraction_problems
from .field_checks import short as _short
from .joints import joint_problems, joints_from_dict, joints_to_dict
from .skin_record import skin_record_from_dict, skin_record_problems
from .topology import Topology
from .traces import traces_from_dict, traces_to_dict

FORMAT = "ellimann.mannequin"
FORMAT_VERSION = 2  # 2: "measured_with" (the reference set and section heights); a version 1 file is female
ROLES = ("base", "reference", "synthesized")
ROTATION_TOL = 1e-6


@dataclass
class Mannequin:
    """A topology with geometry. ``measurements`` are the requested/target tailor measurements in cm.

    ``reference_set`` and ``section_fractions``: the reference set the mannequin belongs to (synthesized from,
    or part of) and the section heights m_T measures it at (fractions of He); the female set's by default.
    ``joints``: None or the (24, 3) rest joint centres in SMPL order (core.mannequin.skeleton, core.mannequin.joints).
    ``skin``: None or how its skin was made (the file's ``skin`` section, core.mannequin.skin_record), so that it can
    be made again.
    """

    topology: Topology
    rotation: np.ndarray
    center: np.ndarray
    semi_axes: np.ndarray
    name: str = ""
    role: str = "synthesized"
    measurements: dict = field(default=None)
    traces: dict = field(default=None)  # {part name: core.mannequin.traces.PartTrace}: what each part was traced from
    reference_set: str = FEMALE_SET
    section_fractions: dict = field(default=None)
    joints: np.ndarray = None
    skin: dict = None

    def __post_init__(self):
        # a copy (mannequins never share one); anything but a dict is left for problems() to name
        fractions = SECTION_FRACTIONS if self.section_fractions is None else self.section_fractions
        self.section_fractions = dict(fractions) if isinstance(fractions, dict) else fractions
        # C-contiguous whatever they came as (a JSON's frames are a transposed view): numpy's sums of products
        # (einsum) take their order from the layout, and a pickled copy (a Dask worker's) is C-contiguous
        self.rotation = np.ascontiguousarray(self.rotation, dtype=float)
        self.center = np.ascontiguousarray(self.center, dtype=float)
        self.semi_axes = np.ascontiguousarray(self.semi_axes, dtype=float)
        self.joints = None if self.joints is None else np.ascontiguousarray(self.joints, dtype=float)

    def __len__(self):
        return len(self.topology)

    def copy(self, **changes):
        values = dict(
            topology=self.topology,
            rotation=self.rotation.copy(),
            center=self.center.copy(),
            semi_axes=self.semi_axes.copy(),
            name=self.name,
            role=self.role,
            measurements=dict(self.measurements) if self.measurements else None,
            traces=dict(self.traces) if self.traces else None,
            reference_set=self.reference_set,
            section_fractions=self.section_fractions,
            joints=None if self.joints is None else self.joints.copy(),
            skin=dict(self.skin) if isinstance(self.skin, dict) else self.skin,
        )
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
                out.append(
                    Problem(
                        part.name,
                        "semi_axes",
                        f"{value:g} m is not a plausible semi-axis (accepted range {low:g} to {high:g} m)",
                    )
                )
            if finite["center"] and far[i]:
                axis = int(np.argmax(np.abs(self.center[i])))
                out.append(
                    Problem(
                        part.name,
                        "center",
                        f"{'xyz'[axis]} = {self.center[i, axis]:g} m is too far from "
                        f"the origin (accepted range {-CENTER_LIMIT:g} to "
                        f"{CENTER_LIMIT:g} m)",
                    )
                )
            if np.all(np.isfinite(self.rotation[i])):
                if ortho_error[i] > ROTATION_TOL:
                    out.append(Problem(part.name, "rotation", f"is not orthonormal (error {ortho_error[i]:.2g})"))
                elif det[i] < 0.0:
                    out.append(Problem(part.name, "rotation", "is a left-handed frame (det -1)"))
        out += measurement_problems(self.measurements)
        if not isinstance(self.reference_set, str) or not self.reference_set:
            out.append(Problem("", "reference_set", f"must be a non-empty name, got {_short(self.reference_set)}"))
        out += section_fraction_problems(self.section_fractions)
        out += [] if self.skin is None else skin_record_problems(self.skin)
        return out + joint_problems(self)

    def check(self):
        """Raise MannequinError listing every problem; return self when valid."""
        problems = self.problems()
        if problems:
            raise MannequinError(problems)
        return self

    def measure(self):
        """m_T in cm as a dict (closed form)."""
        from ..measure.tailor import as_dict, tailor_measurements

        return as_dict(
            tailor_measurements(
                self.rotation, self.center, self.semi_axes, self.topology.girth_mask, self.section_fractions
            )
        )

    def reordered(self, topology):
        """The same mannequin with its parts in ``topology``'s order (which must have the same parts)."""
        problems = self.topology.mismatch(topology)
        if problems:
            raise MannequinError(problems)
        order = np.array([self.topology.index[n] for n in topology.names])
        return self.copy(
            topology=topology, rotation=self.rotation[order], center=self.center[order], semi_axes=self.semi_axes[order]
        )

    def to_dict(self):
        traces = {"traces": traces_to_dict(self.traces)} if self.traces else {}
        joints = {} if self.joints is None else {"joints": joints_to_dict(self.joints)}
        skin = {} if self.skin is None else {"skin": dict(self.skin)}
        return {
            "format": FORMAT,
            "version": FORMAT_VERSION,
            "name": self.name,
            "role": self.role,
            "units": "m",
            "measurements_cm": self.measurements,
            "measured_with": {"reference_set": self.reference_set, "section_fractions": self.section_fractions},
            "ellipsoids": [
                dict(
                    part.to_dict(),
                    center=self.center[i].tolist(),
                    axes=self.rotation[i].T.tolist(),
                    semi_axes=self.semi_axes[i].tolist(),
                )
                for i, part in enumerate(self.topology)
            ],
            **traces,
            **joints,
            **skin,
        }

    @classmethod
    def from_dict(cls, data, check=True):
        """A mannequin from its JSON dict; MannequinError names every field that is missing, of the wrong
        type or implausible (never another exception, whatever ``data`` holds)."""
        if not isinstance(data, dict):
            raise MannequinError(
                [
                    Problem(
                        "",
                        "file",
                        f"holds {_json_type(data)}, not an ElliMann mannequin (an object with format '{FORMAT}')",
                    )
                ]
            )
        if data.get("format") != FORMAT:
            raise MannequinError([Problem("", "format", f"not an ElliMann mannequin (expected format '{FORMAT}')")])
        version = data.get("version")
        if isinstance(version, bool) or not isinstance(version, int) or not 1 <= version <= FORMAT_VERSION:
            raise MannequinError(
                [Problem("", "version", f"is {_short(version)}; this ElliMann reads versions 1 to {FORMAT_VERSION}")]
            )
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
            problems.append(
                Problem(
                    "",
                    "measurements_cm",
                    f"must be an object of He, Sh, Br, Wa, Hi in cm (or null), got {_json_type(measurements)}",
                )
            )
        measured_with = data.get("measured_with") or {}  # absent (version 1): the female set
        if not isinstance(measured_with, dict):
            problems.append(
                Problem(
                    "",
                    "measured_with",
                    f"must be an object (reference_set, section_fractions), got {_json_type(measured_with)}",
                )
            )
            measured_with = {}
        landmarks = {
            "reference_set": measured_with.get("reference_set", FEMALE_SET),
            "section_fractions": measured_with.get("section_fractions", SECTION_FRACTIONS),
        }
        if not isinstance(landmarks["section_fractions"], dict):
            problems.append(
                Problem(
                    "",
                    "measured_with.section_fractions",
                    f"must be an object of Sh, Br, Wa, Hi, got {_json_type(landmarks['section_fractions'])}",
                )
            )
        items = data.get("ellipsoids")
        if not isinstance(items, list) or not items:
            got = "it is missing" if items is None else "it is empty" if items == [] else f"got {_json_type(items)}"
            problems.append(Problem("", "ellipsoids", f"must be a non-empty list of ellipsoid objects; {got}"))
        else:
            problems += [
                Problem(
                    "",
                    f"ellipsoids[{i}]",
                    f"must be an object (name, side, region, girth, depends, "
                    f"center, axes, semi_axes), got {_json_type(item)}",
                )
                for i, item in enumerate(items)
                if not isinstance(item, dict)
            ]
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
        mannequin = cls(
            topology,
            np.swapaxes(np.array(arrays["axes"]), 1, 2),
            np.array(arrays["center"]),
            np.array(arrays["semi_axes"]),
            name=name,
            role=role,
            measurements=measurements,
            traces=traces_from_dict(data.get("traces"), topology.names),
            joints=joints_from_dict(data.get("joints")),
            skin=skin_record_from_dict(data.get("skin")),
            **landmarks,
        )
        return mannequin.check() if check else mannequin

    def to_json(self):
        return json.dumps(self.to_dict(), indent=1)

    def save(self, path):
        atomic_write_text(path, self.to_json() + "\n")

    @classmethod
    def load(cls, path, check=True):
        """Read a mannequin JSON file (UTF-8). Whatever the file holds, a bad one raises MannequinError naming
        the file or the field (OSError if it cannot be opened)."""
        try:
            raw = read_bytes_within(path, what="a mannequin file")
        except TooLargeError as error:
            raise MannequinError([Problem("", "file", str(error))]) from None
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as error:
            encoding = _bom_encoding(raw)
            what = (
                f"is {encoding} text"
                if encoding
                else f"is not UTF-8 text (byte {error.start} is {raw[error.start]:#04x})"
            )
            raise MannequinError([Problem("", "file", f"{path} {what}; mannequin files are JSON in UTF-8")]) from None
        try:
            data = json.loads(text)
        except RecursionError:
            raise MannequinError(
                [Problem("", "file", f"{path} is nested too deeply to be a mannequin (its JSON is 4 levels deep)")]
            ) from None
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
    return (
        np.stack([m.rotation for m in items]),
        np.stack([m.center for m in items]),
        np.stack([m.semi_axes for m in items]),
    )
