"""Building a reference set: from a traced Base Mannequin and N >= 3 bodies of the traced mesh's topology
to N Reference Mannequins that meet their targets (the paper's Sections 2.3.3-2.3.4).

For each body: every part fitted to the same vertices the base's part was traced from (core/fitting/mannequin_fit.py),
axes labelled against the base's, made symmetric and registered; then deformed by synthesis' exact-mode
refinement (core.synthesis.refine: rotations kept, symmetric) until m_T meets the body's targets. The N are then
cleaned together (core.mannequin.clean: registration, symmetry, axis labels against the RM nearest the targets'
mean) and each is checked: clean, every measurement within ``accept_tolerance`` of its target, and how
much of its body it fills (coverage, excess: core/geometry/volume.py). Deterministic: no randomness, fixed
iteration counts and orders. Everything is checked before the first fit, so bad input costs nothing.

What a build returns (BuiltReferenceSet) is the whole set: the RMs, the relabelled base and the manifest (name,
sex, section heights, ranges from the targets, provenance), ready for ``write``; callers add only where the
bodies came from.

Joints: a body with a skeleton (``BodyMesh.joints``) gives its RM joints that go through every step the pieces
go through: mirrored and registered with them, moved by the refinement as points fixed in their anchor parts
(core.mannequin.joints.follow_pieces), translated by the cleaning.
"""

import csv
import math
import pathlib
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field

import numpy as np

from ..errors import ElliMannError, one_line
from ..geometry.frames import is_rotation
from ..geometry.volume import GRID_SPACING, BodyVolume, fill_shares
from ..mannequin.clean import (
    asymmetry,
    clean,
    landmark_indices,
    register_to_world,
    registration_offset,
    relabel,
    symmetrize,
)
from ..mannequin.joints import anchor_indices, follow_pieces
from ..measure.tailor import as_dict, section_heights
from ..measurements import ABSURD_LIMITS, MEASUREMENTS
from ..synthesis.bodies import BODIES_FILE, BodiesError
from ..synthesis.body_space import SPACE_FILE
from ..synthesis.manifest import STEM, Manifest, targets_range, write_reference_set
from ..synthesis.refine import FACTOR_LIMITS, refine
from .body_mesh import mesh_problem
from .mannequin_fit import BuildCancelledError, FitConstants, fit_mannequin
from .reference_bodies import keep_bodies, keep_space

__all__ = [
    "BASE_STEM",
    "BuildCancelledError",
    "BuiltReferenceSet",
    "BuildSettings",
    "BuildReport",
    "ReferenceBuildError",
    "build_reference_set",
    "read_targets",
    "traced_mesh",
    "validate_inputs",
]
MIN_BODIES = 3
BASE_STEM = "base_mannequin"  # the base's file in a built set, unless the caller names it


class ReferenceBuildError(ElliMannError):
    """Input a reference set cannot be built from, or a body whose RM cannot meet its targets (one line)."""


@dataclass(frozen=True)
class BuildSettings:
    fit: FitConstants = field(default_factory=FitConstants)
    # Relative m_T error the refinement aims at: where Newton has converged, so where it stops (an
    # iteration more or less) moves no part by more than rounding.
    adjust_tolerance: float = 1e-12
    adjust_iterations: int = 40
    accept_tolerance: float = 5e-3  # what every RM must meet after cleaning (0.5 %)
    check_spacing: float = GRID_SPACING  # m: grid of the coverage check (None: no coverage check)


@dataclass
class BuildReport:
    """What the build found, per RM stem: ``shifts`` (body -> RM translation, m), ``fitted`` (m_T before
    the refinement), ``factors`` (of the refinement), ``errors`` (relative m_T error after cleaning),
    ``fill`` (coverage and excess of ellipsoids and cushions), ``seconds`` per stage; ``base`` relabelled
    against ``reference`` (the RM the others' axes are labelled against)."""

    base: object
    reference: str
    shifts: dict = field(default_factory=dict)
    fitted: dict = field(default_factory=dict)
    factors: dict = field(default_factory=dict)
    errors: dict = field(default_factory=dict)
    fill: dict = field(default_factory=dict)
    seconds: dict = field(default_factory=dict)

    def worst(self, stem):
        """(measurement, relative error) of the RM's largest error."""
        key = max(self.errors[stem], key=lambda k: abs(self.errors[stem][k]))
        return key, self.errors[stem][key]


@dataclass
class BuiltReferenceSet:
    """A built set: ``mannequins`` ({stem: RM}, each of the set), ``base`` (relabelled against the reference RM,
    saved as ``manifest.base``), ``manifest`` and the build's ``report``."""

    mannequins: dict
    base: object
    manifest: Manifest
    report: BuildReport
    bodies: object = None  # the bodies it was built from (core.synthesis.bodies.SetBodies), when given their labels
    space: object = None  # their body space (core.synthesis.body_space.BodySpace), from MIN_SPACE_BODIES bodies

    @classmethod
    def assemble(
        cls, rms, report, targets, name, sex=None, base_stem=BASE_STEM, provenance=None, bodies=None, space=None
    ):
        """The set of the cleaned ``rms`` ({stem: RM}) and ``report`` (its base relabelled): each made the set's
        (``reference_set`` = ``name``), and their manifest, its ranges the targets' min-max; ``bodies`` (SetBodies)
        and ``space`` (BodySpace) kept as the set's bodies and body-space files."""
        stems = list(rms)
        manifest = Manifest(
            name=name,
            mannequins=stems,
            sex=sex,
            base=base_stem,
            section_fractions=dict(report.base.section_fractions),
            ranges_cm=targets_range({stem: targets[stem] for stem in stems}),
            targets_cm={stem: dict(targets[stem]) for stem in stems},
            provenance={**(provenance or {}), "labelled_against": report.reference},
            bodies=BODIES_FILE if bodies is not None else None,
            body_space=SPACE_FILE if space is not None else None,
        )
        mannequins = {stem: rm.copy(reference_set=name) for stem, rm in rms.items()}
        return cls(mannequins, report.base.copy(reference_set=name), manifest, report, bodies, space)

    def write(self, folder):
        """Write the set into ``folder`` (each file atomically, its bodies before the manifest, the manifest last);
        returns the paths."""
        written = []
        if self.bodies is not None:
            written.append(self.bodies.save(pathlib.Path(folder) / self.manifest.bodies))
        if self.space is not None:
            written.append(self.space.save(pathlib.Path(folder) / self.manifest.body_space))
        return written + write_reference_set(folder, self.mannequins, self.manifest, base=self.base)


def traced_mesh(base):
    """{traced_mesh, vertex_count}: the mesh ``base``'s selections were traced on, for a manifest's provenance."""
    first = next(iter(base.traces.values()))
    return {"traced_mesh": first.mesh, "vertex_count": first.vertex_count}


def display_name(stem):
    """'small_chubby' -> 'Small Chubby'."""
    return " ".join(word.capitalize() for word in stem.replace("-", "_").split("_") if word)


def _traced_parts(topology):
    return [part.name for part in topology if part.side != "R"]


def read_targets(path):
    """{name: {He, Sh, Br, Wa, Hi: cm}} from a CSV with a 'name' column and a column per measurement (or
    target_He, ...); rows without values (a traced body that is no RM) are left out. ReferenceBuildError
    naming the file, the line and the field."""
    try:
        with open(path, encoding="utf-8-sig", newline="") as stream:
            rows = list(csv.DictReader(stream))
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        raise ReferenceBuildError(f"{path}: cannot be read ({one_line(error)})") from None
    if not rows or "name" not in rows[0]:
        raise ReferenceBuildError(f"{path}: needs a header with a 'name' column and {', '.join(MEASUREMENTS)}")
    columns = {}
    for key in MEASUREMENTS:
        column = next((c for c in (key, f"target_{key}") if c in rows[0]), None)
        if column is None:
            raise ReferenceBuildError(f"{path}: has no {key} column (cm)")
        columns[key] = column
    targets = {}
    for line, row in enumerate(rows, 2):
        name = (row.get("name") or "").strip()
        values = {key: (row.get(column) or "").strip() for key, column in columns.items()}
        if not name or not any(values.values()):
            continue  # a body without targets (e.g. the traced one) is no RM
        if name in targets:
            raise ReferenceBuildError(f"{path}: line {line}: '{name}' has a second row")
        try:
            targets[name] = {key: float(value) for key, value in values.items()}
        except ValueError:
            bad = next(key for key, value in values.items() if not _is_number(value))
            raise ReferenceBuildError(f"{path}: line {line}: {bad}={values[bad]!r} is not a number (cm)") from None
    return targets


def _is_number(text):
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


def validate_inputs(base, bodies, targets, minimum=MIN_BODIES):
    """Raise ReferenceBuildError (one line) for anything a build cannot start from; returns the traced mesh's
    (name, vertex count). ``bodies``: BodyMesh list (``minimum`` of them); ``targets``: {name: {measurement: cm}}."""
    if len(bodies) < minimum:
        raise ReferenceBuildError(f"bodies: a reference set needs at least {minimum} bodies, got {len(bodies)}")
    names = [body.name for body in bodies]
    twice = sorted({name for name in names if names.count(name) > 1})
    if twice:
        raise ReferenceBuildError(
            f"bodies: two bodies are named '{twice[0]}'; each body's name (file stem) names its Reference Mannequin"
        )
    traces = base.traces or {}
    missing = [name for name in _traced_parts(base.topology) if name not in traces]
    if missing and traces:  # some recorded: parts added to a traced base (a finer topology) and never fitted
        raise ReferenceBuildError(
            f"base '{base.name}': '{missing[0]}' has no recorded selection ({len(missing)} of its "
            f"{len(_traced_parts(base.topology))} left and central parts have none): in Blender select its vertices on "
            "the body mesh in Edit Mode and run Fit Ellipsoid (Trace panel), then save the base"
        )
    if missing:
        raise ReferenceBuildError(
            f"base '{base.name}': {len(missing)} of its {len(_traced_parts(base.topology))} left and central parts "
            f"have no recorded selection (first: '{missing[0]}'); it was traced before ElliMann recorded "
            "selections: in Blender select each part's vertices on the body mesh in Edit Mode and run Fit "
            "Ellipsoid again (Trace panel), then save the base"
        )
    used = [traces[name] for name in _traced_parts(base.topology)]
    first = used[0]
    other = next((t for t in used if (t.vertex_count, t.edges_crc) != (first.vertex_count, first.edges_crc)), None)
    if other is not None:
        raise ReferenceBuildError(
            f"base '{base.name}': its parts were traced on different meshes ('{first.mesh}', "
            f"{first.vertex_count} vertices, and '{other.mesh}', {other.vertex_count}); "
            "trace every part on one mesh"
        )
    for body in bodies:
        count = len(body.vertices)
        if count != first.vertex_count:
            raise ReferenceBuildError(
                f"{body.name}: has {count} vertices, the base was traced on '{first.mesh}' with "
                f"{first.vertex_count}; bodies must share the traced mesh's topology (fitting "
                "across topologies is not supported)"
            )
        if body.edges_crc != first.edges_crc:
            raise ReferenceBuildError(
                f"{body.name}: has the {count} vertices of '{first.mesh}' but its faces join "
                "other vertices (a shuffled vertex order, or another mesh): bodies must "
                "share the traced mesh's vertex order"
            )
        problem = mesh_problem(body)
        if problem:
            raise ReferenceBuildError(f"{body.name}: {problem}")
    _check_targets(names, targets)
    return first.mesh, first.vertex_count


def _check_targets(names, targets):
    for name in names:
        row = targets.get(name)
        if row is None:
            raise ReferenceBuildError(f"targets: no row for body '{name}' (a row per body, named by its file stem)")
        for key in MEASUREMENTS:
            value = row.get(key)
            low, high = ABSURD_LIMITS[key]
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ReferenceBuildError(f"targets: '{name}' {key} is missing or not a number (cm, {low:g}-{high:g})")
            if not low <= value <= high:
                raise ReferenceBuildError(
                    f"targets: '{name}' {key}={value:g} cm is not a plausible value "
                    f"(accepted range {low:g}-{high:g} cm)"
                )
    for j, b in enumerate(names):
        for a in names[:j]:
            if all(abs(targets[a][k] - targets[b][k]) <= 1e-9 for k in MEASUREMENTS):
                raise ReferenceBuildError(
                    f"targets: '{a}' and '{b}' have the same targets; synthesis interpolates "
                    "between distinct reference points"
                )


def central_body(names, targets):
    """The body whose targets are nearest the mean of all (in log space): the RM the others are labelled against."""
    logs = np.log([[targets[name][key] for key in MEASUREMENTS] for name in names])
    return names[int(np.argmin(((logs - logs.mean(axis=0)) ** 2).sum(axis=1)))]


def adjust(mannequin, targets, settings):
    """``mannequin`` deformed until m_T meets ``targets`` (cm): (mannequin, factors dict). Raises
    ReferenceBuildError naming the measurement and how far it stays when a factor limit stops it."""
    wanted = np.array([[targets[key] for key in MEASUREMENTS]])
    result = refine(
        mannequin.topology,
        mannequin.rotation[None],
        mannequin.center[None],
        mannequin.semi_axes[None],
        wanted,
        tolerance=settings.adjust_tolerance,
        max_iterations=settings.adjust_iterations,
        fractions=mannequin.section_fractions,
    )
    factors = as_dict(result.factors[0])
    if not result.converged[0]:
        errors = result.measured[0] / wanted[0] - 1.0
        k = int(np.argmax(np.abs(errors)))
        key = MEASUREMENTS[k]
        limited = [
            m for m in MEASUREMENTS if not FACTOR_LIMITS[0] * (1 + 1e-9) < factors[m] < FACTOR_LIMITS[1] * (1 - 1e-9)
        ]
        why = (
            f"the refinement's factor limits ({FACTOR_LIMITS[0]:g} to {FACTOR_LIMITS[1]:.4g}) stop {', '.join(limited)}"
            if limited
            else "the refinement did not converge"
        )
        raise ReferenceBuildError(
            f"targets: '{mannequin.name}' cannot reach {key}={wanted[0, k]:g} cm: it stays at "
            f"{result.measured[0, k]:.2f} cm ({errors[k]:+.2%}); {why}. Use a body nearer its targets"
        )
    joints = (
        None
        if mannequin.joints is None
        else follow_pieces(
            mannequin.joints,
            anchor_indices(mannequin.topology),
            (mannequin.rotation, mannequin.center, mannequin.semi_axes),
            (mannequin.rotation, result.center[0], result.semi_axes[0]),
        )
    )
    return mannequin.copy(center=result.center[0], semi_axes=result.semi_axes[0], joints=joints), factors


def cleanliness_problems(mannequin, tol=1e-9):
    """What keeps a mannequin from being clean: left-handed frames, asymmetry, not registered."""
    problems = []
    if not np.all(is_rotation(mannequin.rotation, tol)):
        problems.append("a frame is not a rotation")
    if asymmetry(mannequin) > tol:
        problems.append(f"asymmetric by {asymmetry(mannequin):.2g} m")
    floor = float(section_heights(mannequin.rotation, mannequin.center, mannequin.semi_axes)[0])
    if abs(floor) > tol:
        problems.append(f"lowest point at z = {floor:.2g} m")
    landmark = mannequin.center[landmark_indices(mannequin.topology)].mean(axis=0)
    if np.any(np.abs(landmark[:2]) > tol):
        problems.append(f"trapezius centroid at x, y = {landmark[0]:.2g}, {landmark[1]:.2g} m")
    return problems


def relative_errors(measured, targets):
    return {key: measured[key] / targets[key] - 1.0 for key in MEASUREMENTS}


def accept_cleaned(name, rm, targets, report, settings):
    """Record a cleaned RM's m_T errors in ``report``; ReferenceBuildError when it is off its targets by more than
    the accepted tolerance or is not clean."""
    report.errors[name] = relative_errors(rm.measure(), targets)
    key, error = report.worst(name)
    if abs(error) > settings.accept_tolerance:
        raise ReferenceBuildError(
            f"{name}: after cleaning m_T {key} is off its target by {error:.3%} (accepted "
            f"{settings.accept_tolerance:.1%})"
        )
    problems = cleanliness_problems(rm.check())
    if problems:
        raise ReferenceBuildError(f"{name}: {'; '.join(problems)}")


def fit_body(base, body, targets, settings, cancel=None):
    """One body's RM before the set is cleaned: (name, body -> RM shift, m_T as fitted, RM, refinement factors)."""
    fitted, _ = fit_mannequin(
        body,
        base.topology,
        base.traces,
        base,
        _kept(base),
        settings.fit,
        cancel,
        name=display_name(body.name),
        role="reference",
        measurements=dict(targets),
    )
    fitted = symmetrize(fitted.copy(joints=body.joints))
    shift = registration_offset(fitted)
    fitted = register_to_world(fitted)
    rm, factors = adjust(fitted, targets, settings)
    return body.name, shift, fitted.measure(), rm, factors


def _kept(base):
    """Per part, the axis of the base part's frame its fit took from the points (recorded in its trace)."""
    return [base.traces[part.name].fit.kept if part.name in base.traces else None for part in base.topology]


def build_reference_set(
    base,
    bodies,
    targets,
    progress=None,
    cancel=None,
    settings=None,
    reference=None,
    workers=1,
    name=None,
    sex=None,
    base_stem=BASE_STEM,
    provenance=None,
    body_labels=None,
):
    """N Reference Mannequins from ``base`` (a Mannequin with traces) and ``bodies`` (BodyMesh, N >= 3).

    ``targets``: {body name: {He, Sh, Br, Wa, Hi: cm}}; ``progress(fraction, text)`` is called as the
    work goes on; ``cancel()`` is polled between parts and stops the build (BuildCancelledError) when true;
    ``reference``: the body whose RM the others' axes are labelled against (default: the one nearest
    the targets' mean); ``workers``: processes fitting bodies at once (each body is fitted alike whichever
    process fits it, so the result does not depend on it; with more than one, ``cancel`` is polled between
    bodies). ``name`` (default: the base's set's), ``sex``, ``base_stem`` (the base's file) and ``provenance``
    (where the base and bodies came from; the build adds the RM it labelled against) go into the manifest.
    ``body_labels`` (core.synthesis.bodies.BodyLabels of the bodies' topology): the bodies are kept with the set
    (``bodies.npz``, for the body skin: core.body), each with its joints, and from MIN_SPACE_BODIES bodies their
    body space (``body_space.npz``: core.synthesis.body_space, each body measured); without, the set has no bodies.
    Returns a BuiltReferenceSet. Raises ReferenceBuildError (one line) before any work for bad input, or when an
    RM cannot meet its targets.
    """
    # by default measured at the base's section heights (its own set's): the fit keeps clear of them and
    # the refinement meets the targets at them
    settings = settings or BuildSettings(fit=FitConstants(section_fractions=dict(base.section_fractions)))
    validate_inputs(base, bodies, targets)
    names = [body.name for body in bodies]
    name = name or base.reference_set
    if not STEM.match(base_stem) or base_stem in names:
        raise ReferenceBuildError(f"base_stem: '{base_stem}' must be letters, digits, _ . - and no body's name")
    reference = reference or central_body(names, targets)
    if reference not in names:
        raise ReferenceBuildError(f"reference: '{reference}' is not one of the bodies ({', '.join(names)})")
    report = BuildReport(base=None, reference=reference)
    steps = len(bodies) + (1 if settings.check_spacing else 0)

    def tell(done, text):
        if progress is not None:
            progress(done / steps, text)

    started = time.perf_counter()
    fitted = {}
    jobs = [(base, body, targets[body.name], settings) for body in bodies]
    if workers > 1 and len(bodies) > 1:
        pool = ProcessPoolExecutor(min(workers, len(bodies)))
        try:
            futures = [pool.submit(fit_body, *job) for job in jobs]
            for k, future in enumerate(as_completed(futures)):
                if cancel is not None and cancel():
                    raise BuildCancelledError()
                stem, *result = future.result()
                fitted[stem] = result
                tell(k + 1, f"fitted {stem} ({k + 1} of {len(bodies)})")
        finally:  # a failed or cancelled build does not wait for the bodies still being fitted
            pool.shutdown(wait=False, cancel_futures=True)
    else:
        for k, job in enumerate(jobs):
            tell(k, f"fitting {job[1].name} ({k + 1} of {len(bodies)})")
            stem, *result = fit_body(*job, cancel=cancel)
            fitted[stem] = result
    adjusted = []
    for stem in names:
        report.shifts[stem], report.fitted[stem], rm, report.factors[stem] = fitted[stem]
        adjusted.append(rm)
    report.seconds["fit and refine"] = time.perf_counter() - started

    cleaned = clean(adjusted, reference_index=names.index(reference))
    rms = dict(zip(names, cleaned))
    for stem, before in zip(names, adjusted):
        # cleaning a symmetric mannequin only translates it
        report.shifts[stem] = report.shifts[stem] + (rms[stem].center - before.center).mean(axis=0)
    report.base = relabel(base, rms[reference])
    for stem, rm in rms.items():
        accept_cleaned(stem, rm, targets[stem], report, settings)
    if settings.check_spacing:
        tell(len(bodies), "checking how each RM fills its body")
        started = time.perf_counter()
        for body in bodies:
            if cancel is not None and cancel():
                raise BuildCancelledError()
            volume = BodyVolume(body.vertices + report.shifts[body.name], body.faces)
            report.fill[body.name] = fill_shares(volume.grid(settings.check_spacing), rms[body.name])
        report.seconds["coverage check"] = time.perf_counter() - started
    tell(steps, "built")
    try:
        kept = None if body_labels is None else keep_bodies(bodies, body_labels, base.section_fractions)
        space = None if kept is None else keep_space(bodies, body_labels, base.section_fractions, progress)
    except BodiesError as error:
        raise ReferenceBuildError(str(error)) from None
    return BuiltReferenceSet.assemble(rms, report, targets, name, sex, base_stem, provenance, kept, space)
