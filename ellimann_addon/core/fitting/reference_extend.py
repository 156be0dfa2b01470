"""Adding bodies to a reference set already built, without rebuilding the rest (issue 43): each new body fitted,
registered, made symmetric and refined as a build does (core.fitting.reference_build.fit_body: an RM depends only on
its own body), then cleaned with the set's reference RM (the one its others' axes are labelled against: the
manifest's provenance), so the new RMs' axes agree with the old. The manifest gains the new stems and targets (its
ranges the min-max of all), the bodies file the new bodies, and the body space is made again from all of them
(the old bodies' measurements kept, the new ones measured). The RMs already there are not touched.
"""

import pathlib
import time

import numpy as np

from ..mannequin.clean import clean
from ..mannequin.model import Mannequin
from ..synthesis.bodies import BODIES_FILE, BodiesError, load_set_bodies
from ..synthesis.body_space import (
    MIN_SPACE_BODIES,
    SPACE_FILE,
    SPACE_MEASUREMENTS,
    duplicate_bodies,
    fused_sections,
    load_set_body_space,
    measure_for_space,
    space_from_arrays,
)
from ..synthesis.manifest import read_manifest, targets_range
from .body_mesh import BodyMesh
from .reference_bodies import keep_bodies
from .reference_build import (
    BuildCancelledError,
    BuildReport,
    BuildSettings,
    BuiltReferenceSet,
    FitConstants,
    ReferenceBuildError,
    accept_cleaned,
    central_body,
    fit_body,
    validate_inputs,
)


def extend_reference_set(folder, bodies, targets, progress=None, cancel=None, settings=None, body_labels=None):
    """A BuiltReferenceSet holding the RMs of ``bodies`` (BodyMesh, one or more, named apart from the set's RMs)
    fitted into the set in ``folder`` (its base, its reference RM) and the set's new manifest, bodies and body space:
    ``write(folder)`` adds them (the RMs there stay as they are). ``targets``: {body name: {He..Hi: cm}};
    ``progress(fraction, text)``, ``cancel()`` as build_reference_set's; ``body_labels`` (BodyLabels) to keep the
    new bodies beside the set's (a set with a bodies file needs them). ReferenceBuildError (one line) before any
    work for bad input, or when an RM cannot meet its targets."""
    folder = pathlib.Path(folder)
    manifest = read_manifest(folder)
    if manifest is None or manifest.base is None:
        raise ReferenceBuildError(f"{folder}: is no reference set with a base (its reference_set.json names none)")
    base = Mannequin.load(folder / f"{manifest.base}.json")
    settings = settings or BuildSettings(fit=FitConstants(section_fractions=dict(base.section_fractions)))
    validate_inputs(base, bodies, targets, minimum=1)
    taken = [body.name for body in bodies if body.name in manifest.mannequins or body.name == manifest.base]
    if taken:
        raise ReferenceBuildError(f"bodies: '{taken[0]}' is already a mannequin of the set in {folder}")
    for body in bodies:
        same = [stem for stem, row in manifest.targets_cm.items() if row == dict(targets[body.name])]
        if same:
            raise ReferenceBuildError(
                f"targets: '{body.name}' and the set's '{same[0]}' have the same targets; synthesis interpolates "
                "between distinct reference points"
            )
    old_bodies = load_set_bodies(folder) if manifest.bodies else None
    if old_bodies is not None and body_labels is None:
        raise ReferenceBuildError(f"body_labels: the set in {folder} keeps its bodies; give the new bodies' labels")
    stems = list(manifest.mannequins)
    reference = manifest.provenance.get("labelled_against")
    if reference not in stems:
        reference = central_body(stems, manifest.targets_cm)
    reference_rm = Mannequin.load(folder / f"{reference}.json")

    report = BuildReport(base=base, reference=reference)
    started = time.perf_counter()
    adjusted = []
    for k, body in enumerate(bodies):
        if progress is not None:
            progress(k / len(bodies), f"fitting {body.name} ({k + 1} of {len(bodies)})")
        if cancel is not None and cancel():
            raise BuildCancelledError()
        stem, shift, fitted, rm, factors = fit_body(base, body, targets[body.name], settings, cancel)
        report.shifts[stem], report.fitted[stem], report.factors[stem] = shift, fitted, factors
        adjusted.append(rm)
    report.seconds["fit and refine"] = time.perf_counter() - started
    cleaned = clean([reference_rm, *adjusted], reference_index=0)[1:]
    rms = {}
    for body, before, rm in zip(bodies, adjusted, cleaned):
        report.shifts[body.name] = report.shifts[body.name] + (rm.center - before.center).mean(axis=0)
        accept_cleaned(body.name, rm, targets[body.name], report, settings)
        rms[body.name] = rm.copy(reference_set=manifest.name)

    manifest.mannequins = stems + list(rms)
    manifest.targets_cm = {**manifest.targets_cm, **{name: dict(targets[name]) for name in rms}}
    manifest.ranges_cm = targets_range(manifest.targets_cm)
    manifest.provenance = {**manifest.provenance, "added": [*manifest.provenance.get("added", []), *rms]}
    kept = space = None
    try:
        if old_bodies is not None:
            old = [
                BodyMesh(name, old_bodies.vertices(i), old_bodies.faces, 0, old_bodies.joints[i])
                for i, name in enumerate(old_bodies.names)
            ]  # the set's bodies again (within float16's rounding), then the new ones
            kept = keep_bodies(old + list(bodies), body_labels, base.section_fractions)
            space = grown_space(folder, kept, progress)
    except BodiesError as error:
        raise ReferenceBuildError(str(error)) from None
    manifest.bodies = BODIES_FILE if kept is not None else manifest.bodies
    manifest.body_space = SPACE_FILE if space is not None else manifest.body_space
    if progress is not None:
        progress(1.0, f"added {len(rms)} bodies")
    return BuiltReferenceSet(rms, None, manifest, report, kept, space)


def grown_space(folder, bodies, progress=None):
    """The BodySpace of all ``bodies`` (SetBodies), the measurements of those the set's body space already holds
    kept, the others measured; None below MIN_SPACE_BODIES, or when the set's body space holds bodies its bodies
    file does not (the shipped sets': their banks): that space stays."""
    old = load_set_body_space(folder)
    if len(bodies) < MIN_SPACE_BODIES or (old is not None and not set(old.names) <= set(bodies.names)):
        return None
    vertices = bodies.mean + bodies.offsets
    duplicate_bodies(bodies.names, vertices)
    known = {} if old is None else dict(zip(old.names, old.measured))
    measured = []
    for i, name in enumerate(bodies.names):
        if name not in known or (old is not None and old.keys != SPACE_MEASUREMENTS):
            fused = fused_sections(vertices[i], bodies.faces, bodies.arms["L"] | bodies.arms["R"], bodies.fractions)
            if fused:
                raise BodiesError(f"body {name}: an arm touches the torso at the {', '.join(fused)} section")
            values, problems = measure_for_space(bodies.vertices(i), bodies.faces, bodies.fractions, bodies.arms)
            missing = [key for key in SPACE_MEASUREMENTS if key not in values]
            if missing:
                why = f" ({problems[0]})" if problems else ""
                raise BodiesError(f"body {name}: {', '.join(missing)} cannot be measured{why}")
            known[name] = [values[key] for key in SPACE_MEASUREMENTS]
            if progress is not None:
                progress(1.0, f"body space: measured {name}")
        measured.append(known[name])
    return space_from_arrays(bodies.names, vertices, bodies.joints, np.array(measured), bodies.fractions)
