"""The Reference Mannequins a synthesis interpolates: one topology, geometry stacks and measurements, loaded
(and cached) from a folder of JSON files, with what IDW and the refinement precompute on them."""

import math
import os
import pathlib
import sys

import numpy as np

from ..constants import RANGES, REFERENCE_MEASUREMENTS, SECTION_FRACTIONS
from ..errors import MannequinError, ReferenceSetError
from ..geometry.frames import SAGITTAL_REFLECTION
from ..mannequin.clean import asymmetry
from ..mannequin.joints import anchor_indices
from ..mannequin.model import Mannequin
from ..mannequin.skeleton import bone_problems, joint_limb_roots, limb_directions, limb_roots, part_bones
from ..measure.tailor import tailor_measurements
from ..measurements import ABSURD_LIMITS, MEASUREMENTS
from .idw import ZERO_DISTANCE, axis_scale, normalized_points
from .manifest import MANIFEST_FILE, legacy_manifest, read_manifest
from .options import is_number
from .refine import deform_basis, fd_jacobian

REFERENCE_NAMES = tuple(REFERENCE_MEASUREMENTS)  # small_slim, tall_slim, small_chubby, tall_chubby, average


def _shipped_folder():
    """The repository's reference_blends/ (a checkout, the extension), else where ``pip install`` put them
    (``share/ellimann/reference_blends`` under the environment's prefix, or the user's with ``--user``)."""
    checkout = pathlib.Path(__file__).resolve().parents[3] / "reference_blends"
    if checkout.is_dir():
        return checkout
    import site

    prefixes = [sys.prefix, getattr(site, "USER_BASE", None) or site.getuserbase()]
    for prefix in prefixes:
        installed = pathlib.Path(prefix) / "share" / "ellimann" / "reference_blends"
        if installed.is_dir():
            return installed
    return checkout


REFERENCE_FOLDER = _shipped_folder()
SYMMETRY_TOLERANCE = 1e-6  # m: RMs must be symmetric to this for the mirrored synthesis to be exact
_INDEX = {key: i for i, key in enumerate(MEASUREMENTS)}


class ReferenceSet:
    """The Reference Mannequins: one topology, geometry stacks (k, n, ...) and measurements (k, 5) cm.

    ``measurements`` are the RMs' nominal measurements (Table 2.3), the points Eq. 2.1 interpolates
    between. Every RM is reordered to the first one's topology. ``manifest`` (core.synthesis.manifest)
    gives the set's ``name``, ``section_fractions``, ``ranges`` (L, cm) and ``absurd_limits`` (cm); without
    one they are the female constants of core/constants.py.
    """

    def __init__(self, mannequins, names=None, sources=None, manifest=None):
        mannequins = list(mannequins)
        names = list(names or [m.name or f"RM {i + 1}" for i, m in enumerate(mannequins)])
        sources = list(sources or names)
        if len(mannequins) < 2:
            raise ReferenceSetError("", "reference set", f"needs at least 2 mannequins, got {len(mannequins)}")
        first = mannequins[0]
        ordered, measurements = [], []
        for mannequin, source in zip(mannequins, sources):
            problems = mannequin.problems()
            if problems:
                raise ReferenceSetError(source, "geometry", str(MannequinError(problems)))
            mismatch = first.topology.mismatch(mannequin.topology)
            if mismatch:
                raise ReferenceSetError(
                    source, "topology", topology_mismatch(mismatch, len(mannequin), len(first), sources[0])
                )
            mannequin = mannequin.reordered(first.topology) if mannequin.topology != first.topology else mannequin
            ordered.append(mannequin)
            measurements.append(_reference_measurements(mannequin, source))
            off = asymmetry(mannequin)
            if off > SYMMETRY_TOLERANCE:
                raise ReferenceSetError(
                    source, "geometry", f"is not symmetric about x = 0 (asymmetry {off * 1e3:.3g} mm); clean it first"
                )
        self.mannequins = ordered
        self.names = names
        self.manifest = manifest
        self.name = manifest.name if manifest else legacy_manifest().name
        self.section_fractions = dict(manifest.section_fractions) if manifest else dict(SECTION_FRACTIONS)
        self.ranges = {k: tuple(v) for k, v in manifest.ranges_cm.items()} if manifest else dict(RANGES)
        self.absurd_limits = (
            {k: tuple(v) for k, v in manifest.absurd_limits_cm.items()} if manifest else dict(ABSURD_LIMITS)
        )
        self.sources = sources
        self.topology = first.topology
        self.measurements = np.array(measurements)
        self.mirror_label_mismatch = []  # right parts whose axis labels differ between RMs
        self.rotation = np.stack([m.rotation for m in ordered])
        self.center = np.stack([m.center for m in ordered])
        self.semi_axes = np.stack([m.semi_axes for m in ordered])
        # (k, 24, 3) rest joints when every RM has them (core.synthesis.idw.interpolate_joints), else None
        self.joints = np.stack([m.joints for m in ordered]) if all(m.joints is not None for m in ordered) else None
        for j in range(len(ordered)):
            for i in range(j):
                if np.allclose(self.measurements[i], self.measurements[j]):
                    raise ReferenceSetError(
                        sources[j],
                        "measurements_cm",
                        f"are the same as those of {sources[i]}; IDW needs distinct reference points",
                    )
        topology = self.topology
        self._left = topology.indices("L")
        self._right = topology.twin_indices[self._left]
        self._central = topology.indices("C")
        self._source = np.concatenate([self._left, self._central]).astype(int)
        self._mirror_signs = self._find_mirror_signs()
        mask = topology.dependency_mask[self._source].astype(float)  # (s, 5)
        self._mask = mask
        # coincide[s, j, l]: RMs j and l have the same measurements in part s's sub-space.
        diff = np.abs(self.measurements[:, None, :] - self.measurements[None, :, :])  # (k, k, 5)
        self._coincide = np.all((diff[None] <= ZERO_DISTANCE) | (mask[:, None, None, :] == 0.0), axis=-1)
        # Proportional IDW: a part's heights go with He, its widths with the geometric mean of the
        # other measurements it depends on (one for every part of the shipped topology); only with
        # measurements it depends on, so it stays a function of its own sub-space.
        he = _INDEX["He"]
        self._height_exponent = np.zeros_like(mask)
        self._height_exponent[:, he] = mask[:, he]
        widths = mask.copy()
        widths[:, he] = 0.0
        self._width_exponent = widths / np.maximum(widths.sum(axis=1, keepdims=True), 1.0)
        self._size_origin = self.measurements.mean(axis=0)  # scales are relative to the RMs' mean
        self._limb_root, self._limb_along = self._limbs()
        self._normalized = {}
        self._jacobian = None

    def __len__(self):
        return len(self.mannequins)

    def check_topology(self, mannequin, source):
        """Raise ReferenceSetError (one line naming ``source``) if ``mannequin`` is not of the set's topology: a
        mannequin of the 40 measured or updated with the fine set's landmarks, or the other way round."""
        mismatch = self.topology.mismatch(mannequin.topology)
        if mismatch:
            raise ReferenceSetError(
                source, "topology", topology_mismatch(mismatch, len(mannequin), len(self.topology), f"set {self.name}")
            )

    def size_scales(self, measurements, normalize):
        """Horizontal and vertical scale (..., s) of each interpolated part at ``measurements`` (..., 5) cm.

        1 at the mean of the RMs' measurements; ones throughout for ``normalize="none"``.
        """
        log = np.log(np.asarray(measurements, dtype=float) / self._size_origin)
        ones = np.ones(log.shape[:-1] + (len(self._source),))
        if normalize == "none":
            return ones, ones
        vertical = np.exp(log @ self._height_exponent.T)
        horizontal = np.exp(log @ self._width_exponent.T) if normalize == "proportional" else ones
        return horizontal, vertical

    def refine_jacobian(self):
        """(5, 5) d log m_T / d log factor of the refinement, the mean over the RMs (computed once).

        Exact mode starts its Broyden updates from it instead of five m_T per mannequin: the
        deformation acts alike on every body (its entries vary by a few hundredths between the RMs).
        """
        if self._jacobian is None:
            girth = self.topology.girth_mask
            fractions = self.section_fractions
            measured = tailor_measurements(self.rotation, self.center, self.semi_axes, girth, fractions)
            basis = deform_basis(self.topology, self.rotation, self.center, self.semi_axes, measured, fractions)
            each = fd_jacobian(
                basis,
                np.arange(len(self)),
                self.rotation,
                self.center,
                self.semi_axes,
                np.zeros((len(self), len(MEASUREMENTS))),
                np.log(measured),
                girth,
            )
            self._jacobian = each.mean(axis=0)
        return self._jacobian

    def _limbs(self):
        """(s,) root joint of the limb each interpolated part hangs from and (s, 3) that limb's direction (-1 and
        zeros for the others): what normalized IDW scales in the limb's own axes (core.synthesis.idw
        .normalized_points); ``limb_directions`` {root joint index: unit direction, the RMs' mean}. None of it
        (every part its own anchor, as before) if the RMs have no joints, or if a limb's pieces or joints do not
        share its root joint's anchor part's measurements: only then do they meet at the same root."""
        count = len(self._source)
        none = np.full(count, -1), np.zeros((count, 3))
        self.limb_directions = {}
        if self.joints is None or bone_problems(self.topology):
            return none
        try:
            anchors = anchor_indices(self.topology)
        except MannequinError:
            return none
        roots = limb_roots(part_bones(self.topology)[self._source])
        mask = self.topology.dependency_mask
        below = joint_limb_roots()
        pairs = [(int(part), anchors[root]) for part, root in zip(self._source, roots) if root >= 0]
        pairs += [(anchors[j], anchors[root]) for j, root in enumerate(below) if root >= 0]
        if any(not np.array_equal(mask[a], mask[b]) for a, b in pairs):
            return none
        self.limb_directions = limb_directions(self.joints)
        along = np.array([self.limb_directions[r] if r >= 0 else np.zeros(3) for r in roots])
        return roots, along

    def normalized_geometry(self, normalize):
        """The RMs' geometry of the interpolated parts divided by their own scales: the centres' three parts
        (k, s, 3, 3) (core.synthesis.idw.normalized_points: a limb's part anchored at its limb's root joint) and
        the semi-axes (k, s, 3)."""
        if normalize not in self._normalized:
            src = self._source
            horizontal, vertical = self.size_scales(self.measurements, normalize)
            center = self.center[:, src]
            limb = self._limb_root >= 0
            roots = np.where(limb[:, None], self.joints[:, self._limb_root], center) if limb.any() else center
            parts = normalized_points(center, roots, self._limb_along, horizontal, vertical)
            semi_axes = self.semi_axes[:, src] / axis_scale(
                self.rotation[:, src], horizontal, vertical, self._limb_along
            )
            self._normalized[normalize] = (parts, semi_axes)
        return self._normalized[normalize]

    def normalized_joints(self, normalize, own, slots):
        """The RMs' joints ``own`` divided by the scales of their anchor parts (``slots``, interpolated parts):
        (k, J, 3, 3), as ``normalized_geometry``'s centres (a joint below a limb's root anchored at the root)."""
        key = ("joints", normalize)
        if key not in self._normalized:
            roots = joint_limb_roots()[own]
            roots = np.where(np.isin(roots, list(self.limb_directions)), roots, -1)  # limbs the pieces have too
            along = np.array([self.limb_directions.get(int(r), np.zeros(3)) for r in roots])
            horizontal, vertical = self.size_scales(self.measurements, normalize)  # (k, s)
            joints = self.joints[:, own]
            root_points = np.where(roots[:, None] >= 0, self.joints[:, np.maximum(roots, 0)], joints)
            self._normalized[key] = normalized_points(
                joints, root_points, along, horizontal[:, slots], vertical[:, slots]
            )
        return self._normalized[key]

    def _find_mirror_signs(self):
        """Per left part, the axis signs that turn its sagittal reflection into the right twin's frame.

        Taken from the RMs (after ``clean.clean`` they all agree). Where they do not, the pattern most
        RMs use wins: the right ellipsoid is the same set either way, only its axis labels differ.
        """
        if not len(self._left):
            return np.ones((0, 3))
        reflected = SAGITTAL_REFLECTION @ self.rotation[:, self._left]  # (k, l, 3, 3)
        agreement = np.swapaxes(reflected, -1, -2) @ self.rotation[:, self._right]  # diag(signs) if mirrored
        signs = np.where(np.diagonal(agreement, axis1=-2, axis2=-1) >= 0.0, 1.0, -1.0)  # (k, l, 3)
        mirrored = np.abs(agreement - signs[..., None] * np.eye(3)).max(axis=(-1, -2)) <= 1e-6  # (k, l)
        chosen = np.empty((len(self._left), 3))
        self.mirror_label_mismatch = []
        for p in range(len(self._left)):
            patterns = [tuple(signs[j, p]) for j in range(len(self)) if mirrored[j, p]]
            if len(set(patterns)) != 1 or len(patterns) != len(self):
                self.mirror_label_mismatch.append(self.topology.names[self._right[p]])
            chosen[p] = max(patterns, key=patterns.count) if patterns else (-1.0, 1.0, 1.0)
        return chosen


def topology_mismatch(mismatch, mine, theirs, other):
    """The line that says why a mannequin of ``mine`` parts does not go with ``other``'s of ``theirs``: its first
    ``mismatch`` (Topology.mismatch) or, for two topologies of different sizes (the paper's 40 and the fine one),
    that one set holds one topology."""
    if mine != theirs:
        return (
            f"has {mine} parts and {other} {theirs} ('{mismatch[0].ellipsoid}' is in only one): a reference set holds "
            "mannequins of one topology (the 40 of female and male, or the fine one of female-fine and male-fine)"
        )
    more = f" (and {len(mismatch) - 1} more)" if len(mismatch) > 1 else ""
    return f"differs from {other}: {mismatch[0]}{more}"


def _reference_measurements(mannequin, source):
    me = mannequin.measurements
    if not isinstance(me, dict):
        raise ReferenceSetError(
            source, "measurements_cm", "is missing: a Reference Mannequin needs its He, Sh, Br, Wa, Hi (cm)"
        )
    values = []
    for key in MEASUREMENTS:
        value = me.get(key)
        if value is None:
            raise ReferenceSetError(source, f"measurements_cm.{key}", "is missing")
        if not is_number(value) or not math.isfinite(value) or value <= 0:
            raise ReferenceSetError(
                source, f"measurements_cm.{key}", f"must be a positive finite number, got {value!r}"
            )
        values.append(float(value))
    return values


def load_reference_set(folder=None, names=None):
    """The RMs of a reference-set folder (default: the shipped ``reference_blends/``), one JSON file each: those
    its manifest (``reference_set.json``) lists, or, in a folder without one, ``names`` (default: the five
    female RMs of Table 2.3)."""
    folder = pathlib.Path(folder) if folder is not None else REFERENCE_FOLDER
    if folder.exists() and not folder.is_dir():
        raise ReferenceSetError(
            str(folder),
            "path",
            f"is a file, not a folder (a reference set is the folder holding {MANIFEST_FILE} and the RMs' .json files)",
        )
    if not folder.is_dir():
        raise ReferenceSetError(str(folder), "folder", "does not exist")
    manifest = read_manifest(folder)
    if manifest is not None and names is None:
        names = manifest.mannequins
    names = list(names or REFERENCE_NAMES)
    mannequins, sources = [], []
    for name in names:
        path = folder / f"{name}.json"
        if not path.is_file():
            wanted = f"{MANIFEST_FILE} lists" if manifest else "a folder without a manifest needs"
            raise ReferenceSetError(str(path), "file", f"is missing ({wanted} {', '.join(names)} .json)")
        try:
            mannequins.append(Mannequin.load(path))
        except (MannequinError, OSError, UnicodeDecodeError) as error:
            raise ReferenceSetError(str(path), "file", f"cannot be read: {error}") from None
        sources.append(str(path))
    return ReferenceSet(mannequins, names=names, sources=sources, manifest=manifest)


def _stamp(folder):
    """Modification times of the manifest and the RM files it (or the legacy layout) names."""
    try:
        manifest = read_manifest(folder)
    except ReferenceSetError:
        return None
    names = manifest.mannequins if manifest else REFERENCE_NAMES
    files = [folder / f"{n}.json" for n in names] + ([folder / MANIFEST_FILE] if manifest else [])
    try:
        return tuple(os.stat(path).st_mtime_ns for path in files)
    except OSError:
        return None


_CACHE = {}


def cached_reference_set(folder=None):
    """load_reference_set, memoised on the files' modification times (for the live panel and batches)."""
    folder = pathlib.Path(folder) if folder else REFERENCE_FOLDER
    stamp = _stamp(folder)
    key = str(folder.resolve())
    hit = _CACHE.get(key)
    if stamp is not None and hit is not None and hit[0] == stamp:
        return hit[1]
    reference = load_reference_set(folder)
    _CACHE[key] = (stamp, reference)
    return reference
