"""A mannequin's topology (paper, Section 2.3.2): its named parts and their rules, as data.

Each part is an ellipsoid with a name in the paper's style (``10.a Trapezius.L``), a side, a body region, whether
it takes part in the girth sections, the measurements it depends on (segmented IDW) and an optional cushion partner
(same number, other letter, same side). A :class:`Topology` checks its parts and answers masks and pairs.
"""

import re
from dataclasses import dataclass

import numpy as np

from ..errors import MannequinError, Problem
from ..measurements import MEASUREMENTS
from .field_checks import short

SIDES = ("L", "R", "C")
NAME_PATTERN = re.compile(r"^(?P<number>\d+)\.(?P<letter>[a-z]) (?P<label>[^.]+?)(?:\.(?P<side>[LR]))?$")


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
        return {
            "name": self.name,
            "side": self.side,
            "region": self.region,
            "girth": self.girth,
            "depends": list(self.depends),
            "partner": self.partner,
        }

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
            problems.append(
                Problem(
                    name,
                    "depends",
                    f"must list measurement names among {', '.join(MEASUREMENTS)}, got {short(depends)}",
                )
            )
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
                out.append(Problem(name, "side", f"is '{part.side}' but the name's suffix says '{side_of_name(name)}'"))
            unknown = [m for m in part.depends if m not in MEASUREMENTS]
            if unknown or not part.depends:
                out.append(
                    Problem(
                        name,
                        "depends",
                        f"must be a non-empty subset of {', '.join(MEASUREMENTS)}"
                        + (f"; unknown {unknown}" if unknown else ""),
                    )
                )
            elif len(set(part.depends)) != len(part.depends):
                out.append(Problem(name, "depends", "lists a measurement twice"))
            if part.side in ("L", "R"):
                twin = seen.get(twin_name(name))
                if twin is None:
                    out.append(Problem(name, "side", f"has no mirror twin '{twin_name(name)}'"))
                elif (twin.region, twin.girth, tuple(sorted(twin.depends))) != (
                    part.region,
                    part.girth,
                    tuple(sorted(part.depends)),
                ):
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
                    out.append(
                        Problem(
                            part.name,
                            "topology",
                            "has different side, region, girth, depends or partner in the other mannequin",
                        )
                    )
        return out


def _letter(name):
    match = NAME_PATTERN.match(name)
    return match.group("letter") if match else name
