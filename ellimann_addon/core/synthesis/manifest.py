"""The reference-set folder: the Reference Mannequins' JSON files and a manifest, ``reference_set.json``
(documented in docs/reference_sets.md):

    {"format": "ellimann-reference-set", "version": 1, "name": str, "sex": "female" | "male" | null,
     "base": stem or null, "mannequins": [stems] (N >= 3), "measurements": ["He", "Sh", "Br", "Wa", "Hi"],
     "section_fractions": {"Sh", "Br", "Wa", "Hi": fraction of He}, "ranges_cm": {key: [lo, hi]},
     "absurd_limits_cm": {key: [lo, hi]}, "targets_cm": {stem: {key: cm}}, "provenance": {...},
     "bodies": file name (optional: the body meshes the RMs were traced from, core.body.bodies),
     "body_space": file name (optional: many bodies as a ridge body model's statistics, core.synthesis.body_space)}

A folder without a manifest is the legacy layout: the five female RMs of Table 2.3 and the constants of
core/constants.py (:func:`legacy_manifest`).
"""

import json
import math
import pathlib
import re
from dataclasses import dataclass, field

from ..constants import FEMALE_SET, RANGES, REFERENCE_MEASUREMENTS, SECTION_FRACTIONS
from ..errors import ReferenceSetError
from ..files import atomic_write_text
from ..measurements import ABSURD_LIMITS, MEASUREMENTS

MANIFEST_FILE = "reference_set.json"
MANIFEST_FORMAT = "ellimann-reference-set"
MANIFEST_VERSION = 1
MIN_MANNEQUINS = 3
SEXES = ("female", "male", None)
STEM = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")  # a file name in the folder, no path
SECTIONS = tuple(SECTION_FRACTIONS)
BODIES_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*\.npz$")  # the bodies file, in the folder


def _pairs(limits):
    return {key: [float(lo), float(hi)] for key, (lo, hi) in limits.items()}


@dataclass
class Manifest:
    name: str
    mannequins: list
    sex: str = None
    base: str = None
    section_fractions: dict = field(default_factory=lambda: dict(SECTION_FRACTIONS))
    ranges_cm: dict = field(default_factory=lambda: _pairs(RANGES))
    absurd_limits_cm: dict = field(default_factory=lambda: _pairs(ABSURD_LIMITS))
    targets_cm: dict = field(default_factory=dict)
    provenance: dict = field(default_factory=dict)
    bodies: str = None  # the set's bodies file in the folder (core.body.bodies), or None: a set without bodies
    body_space: str = None  # the set's body-space file (core.synthesis.body_space), or None: a set without one

    def to_dict(self):
        data = {
            "format": MANIFEST_FORMAT,
            "version": MANIFEST_VERSION,
            "name": self.name,
            "sex": self.sex,
            "base": self.base,
            "mannequins": list(self.mannequins),
            "measurements": list(MEASUREMENTS),
            "section_fractions": dict(self.section_fractions),
            "ranges_cm": _pairs(self.ranges_cm),
            "absurd_limits_cm": _pairs(self.absurd_limits_cm),
            "targets_cm": self.targets_cm,
            "provenance": self.provenance,
        }
        if self.bodies is not None:  # a set without bodies writes the manifest it always wrote
            data["bodies"] = self.bodies
        if self.body_space is not None:
            data["body_space"] = self.body_space
        return data

    @classmethod
    def from_dict(cls, data, source=MANIFEST_FILE):
        """A manifest from its JSON; ReferenceSetError naming the field and what it accepts."""

        def bad(key, why):
            return ReferenceSetError(source, key, why)

        if not isinstance(data, dict) or data.get("format") != MANIFEST_FORMAT:
            raise bad("format", f"is not '{MANIFEST_FORMAT}' (not a reference-set manifest)")
        version = data.get("version")
        if isinstance(version, bool) or not isinstance(version, int) or not 1 <= version <= MANIFEST_VERSION:
            raise bad("version", f"is {version!r:.20}; this ElliMann reads versions 1 to {MANIFEST_VERSION}")
        name = data.get("name")
        if not isinstance(name, str) or not name.strip():
            raise bad("name", "must be a non-empty string")
        if data.get("sex") not in SEXES:
            raise bad("sex", "must be 'female', 'male' or null")
        stems = data.get("mannequins")
        if not isinstance(stems, list) or len(stems) < MIN_MANNEQUINS:
            raise bad("mannequins", f"must list at least {MIN_MANNEQUINS} file stems (the RMs' <stem>.json)")
        for stem in stems + ([data["base"]] if data.get("base") is not None else []):
            if not isinstance(stem, str) or not STEM.match(stem):
                raise bad("mannequins", f"{stem!r:.40} is not a file stem (letters, digits, _ . -; no folder)")
        if len(set(stems)) != len(stems):
            raise bad("mannequins", "lists a stem twice")
        if data.get("measurements", list(MEASUREMENTS)) != list(MEASUREMENTS):
            raise bad("measurements", f"must be {list(MEASUREMENTS)} (the measurements this ElliMann synthesizes)")
        fractions = data.get("section_fractions", dict(SECTION_FRACTIONS))
        if (
            not isinstance(fractions, dict)
            or set(fractions) != set(SECTIONS)
            or not all(is_number(v) and 0.0 < v < 1.0 for v in fractions.values())
        ):
            raise bad("section_fractions", f"must give {', '.join(SECTIONS)}, each a fraction of He between 0 and 1")
        if not fractions["Hi"] < fractions["Wa"] < fractions["Br"]:  # exact mode's girth blend needs this order
            raise bad(
                "section_fractions",
                f"must have Hi < Wa < Br, got Hi {fractions['Hi']:g}, Wa {fractions['Wa']:g}, Br {fractions['Br']:g}",
            )
        absurd = _limits(data.get("absurd_limits_cm", _pairs(ABSURD_LIMITS)), "absurd_limits_cm", bad)
        ranges = _limits(data.get("ranges_cm", _pairs(RANGES)), "ranges_cm", bad)
        for key in MEASUREMENTS:
            if not absurd[key][0] <= ranges[key][0] and ranges[key][1] <= absurd[key][1]:
                raise bad("ranges_cm", f"{key} {ranges[key]} must lie within absurd_limits_cm {absurd[key]}")
        targets = data.get("targets_cm", {})
        if not isinstance(targets, dict) or not all(isinstance(v, dict) for v in targets.values()):
            raise bad("targets_cm", "must be an object {stem: {He, Sh, Br, Wa, Hi: cm}}")
        provenance = data.get("provenance", {})
        if not isinstance(provenance, dict):
            raise bad("provenance", "must be an object")
        bodies = data.get("bodies")
        if bodies is not None and (not isinstance(bodies, str) or not BODIES_NAME.match(bodies)):
            raise bad("bodies", f"{bodies!r:.40} is not a file name in the folder (letters, digits, _ . -; .npz)")
        space = data.get("body_space")
        if space is not None and (not isinstance(space, str) or not BODIES_NAME.match(space)):
            raise bad("body_space", f"{space!r:.40} is not a file name in the folder (letters, digits, _ . -; .npz)")
        return cls(
            name,
            list(stems),
            data.get("sex"),
            data.get("base"),
            {k: float(fractions[k]) for k in SECTIONS},
            ranges,
            absurd,
            targets,
            provenance,
            bodies,
            space,
        )


def is_number(value):
    return not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)


def _limits(value, key, bad):
    if not isinstance(value, dict) or set(value) != set(MEASUREMENTS):
        raise bad(key, f"must give [lo, hi] in cm for each of {', '.join(MEASUREMENTS)}")
    out = {}
    for name in MEASUREMENTS:
        pair = value[name]
        if not (
            isinstance(pair, list) and len(pair) == 2 and all(is_number(v) for v in pair) and 0.0 < pair[0] <= pair[1]
        ):
            raise bad(key, f"{name} must be [lo, hi] with 0 < lo <= hi (cm), got {pair!r:.40}")
        out[name] = [float(pair[0]), float(pair[1])]
    return out


def legacy_manifest():
    """What a folder without a manifest holds: the five female RMs of Table 2.3, today's constants."""
    return Manifest(
        FEMALE_SET,
        list(REFERENCE_MEASUREMENTS),
        sex="female",
        targets_cm={stem: dict(row) for stem, row in REFERENCE_MEASUREMENTS.items()},
    )


def read_manifest(folder):
    """The folder's manifest, or None (the legacy layout); ReferenceSetError for a broken one."""
    path = pathlib.Path(folder) / MANIFEST_FILE
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError, RecursionError) as error:
        raise ReferenceSetError(str(path), "file", f"cannot be read as JSON ({error})") from None
    return Manifest.from_dict(data, str(path))


def targets_range(targets):
    """ranges_cm of a set: the min-max of its targets per measurement (L, like RANGES for Table 2.3)."""
    return {
        key: [min(row[key] for row in targets.values()), max(row[key] for row in targets.values())]
        for key in MEASUREMENTS
    }


def write_reference_set(folder, mannequins, manifest, base=None):
    """Write ``mannequins`` ({stem: Mannequin}), ``base`` (saved as ``manifest.base``) and the manifest into
    ``folder``, each file atomically, the manifest last (a folder whose manifest is there is complete).
    Returns the paths written."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    items = list(mannequins.items()) + ([(manifest.base, base)] if base is not None else [])
    for stem, mannequin in items:
        path = folder / f"{stem}.json"
        mannequin.save(path)
        written.append(path)
    path = folder / MANIFEST_FILE
    atomic_write_text(path, json.dumps(manifest.to_dict(), indent=1) + "\n")
    return written + [path]
