"""Making what a checked job asks (``core.job.request``): the mannequin synthesized (segmented IDW, exact mode, the
extra measurements met), its skin (in exact mode its pieces refined until the skin measures the request), its poses
(a standard pose, a pose file, a clip retargeted and clamped), and what was measured and missed, in one
``core.job.result.Result``. ``synth``, ``pose``, the Synthesize operator and its live steps call :func:`make`; a
batch synthesizes its rows together (``core.synthesis.batch.synthesize_chunk``, on Dask too) and finishes each row
with :func:`finish`."""

from ..measure.tailor import as_dict
from ..measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ..synthesis.misses import request_misses, skin_misses
from ..synthesis.synthesize import IDW_EXTRA_NOTE, meet_extra_request, synthesize_checked
from .result import Result, SkinMade


def make(job, progress=None, bones=False):
    """The :class:`Result` of ``job``; ``progress(fraction, message)`` is told as the slow parts go (a skin);
    ``bones``: the skin's bone weights made too (for a rig: the slow part of a skin with joints)."""
    if job.request.mannequin is not None:
        mannequin = job.request.mannequin
        return finish(job, mannequin, None, progress, bones)
    mannequin, measured = synthesize_one(job)
    return finish(job, mannequin, measured, progress, bones)


def synthesize_one(job):
    """(Mannequin, measured {the five and the extra ones asked: cm}) of a job's request: synthesized, and in exact
    mode its extra measurements met."""
    batch = synthesize_checked(job.reference, job.values[None], job.options)
    mannequin, measured, _ = meet_extra_request(
        batch.mannequin(0, job.options.name), as_dict(batch.measured[0]), job.extra, job.options.mode, False
    )
    return mannequin, measured


def finish(job, mannequin, measured, progress=None, bones=False):
    """The :class:`Result` of ``job`` for its synthesized ``mannequin`` (measuring ``measured``: the five and the
    extra ones asked, cm; None for a mannequin already made): its skin, poses and misses."""
    report = progress or (lambda fraction, message: None)
    mode = job.options.mode
    request = None if job.values is None else {**job.five, **job.extra}
    warnings = list(job.warnings)
    if job.extra and mode != "exact":
        warnings.append(IDW_EXTRA_NOTE)
    skin = None
    if job.skin is not None:
        mannequin, measured, skin = _skin(job, mannequin, measured, report, warnings)
        if bones and mannequin.joints is not None:
            report(0.8, "weighting it to the bones")
            skin.skin.bones()
    if request is None:
        missed = []
    elif skin is not None:
        missed = skin_misses(skin.measured, request) if skin.exact else []
    else:
        missed = synthesized_misses(job, measured)
    frames, notes = None, []
    if job.pose is not None:
        frames, clamped, notes = pose_frames(job.pose, mannequin)
        warnings += clamped
    report(0.9, "done")
    return Result(
        mannequin, measured, request, mode, skin, frames, job.pose.fps if job.pose else None, missed, warnings, notes
    )


def synthesized_misses(job, measured):
    """What a job's pieces, measuring ``measured`` ({key: cm}), miss of its request (exact mode only: IDW promises
    no match), as ``core.synthesis.misses.Miss``."""
    return request_misses(measured, job.values, job.extra, job.options.mode)


def _skin(job, mannequin, measured, report, warnings):
    """(pieces, their measurements, SkinMade) of a job's skin. The body skin (``core.body``): the set's bodies
    interpolated for the request and corrected until they measure it, the pieces kept as they are (their joints the
    skin's, where its body bends); asked as "auto", a request no body skin meets gets the skin over the pieces, and a
    warning saying why. The skin over the pieces: in exact mode the pieces refined until it measures the request
    (``core.skin.exact``), else the skin of the pieces as they are, measured on its mesh."""
    settings = job.skin
    if settings.kind == "body":
        from ..body.correct import BodySkinError  # the body skin's code, loaded only when one is asked

        try:
            return _body_skin(job, mannequin, measured, report)
        except BodySkinError as error:
            if job.request.skin.kind != "auto":
                raise
            settings = settings.of_kind("pieces")
            warnings.append(f"{error}; the skin is made over the pieces instead")
    return _pieces_skin(job, settings, mannequin, measured, report)


_MAKERS = {}  # id of a reference set -> (the set, its BodySkinMaker): a set's bodies read and prepared once


def body_skin_maker(reference):
    """The ``core.body.skin.BodySkinMaker`` of a reference set with bodies, made once per set."""
    from ..body.skin import body_skin_maker as make_maker

    kept = _MAKERS.get(id(reference))
    if kept is None or kept[0] is not reference:
        kept = _MAKERS[id(reference)] = (reference, make_maker(reference))
        while len(_MAKERS) > 4:
            del _MAKERS[next(iter(_MAKERS))]
    return kept[1]


def _body_skin(job, mannequin, measured, report):
    """:func:`_skin`'s body skin: for a synthesized mannequin its request, for one already made the request its
    file's skin section records."""
    asked = {**job.five, **job.extra} if job.values is not None else dict((mannequin.skin or {}).get("request", {}))
    five = {key: asked[key] for key in MEASUREMENTS if key in asked}
    if len(five) < len(MEASUREMENTS):
        five = {**dict(mannequin.measurements or {}), **five}
    extra = {key: value for key, value in asked.items() if key in EXTRA_MEASUREMENTS}
    report(0.0, "making the body skin from the set's bodies")
    body = body_skin_maker(job.skin_reference).make(five, extra or None)
    mannequin = mannequin.copy(joints=body.joints)  # the pieces bend where the skin's body does
    body.mannequin, body.settings = mannequin, job.skin
    return mannequin, measured, SkinMade(body, dict(body.measured), True, body.rounds, not body.misses())


def _pieces_skin(job, settings, mannequin, measured, report):
    """:func:`_skin`'s skin over the pieces."""
    from ..skin.exact import exact_skin  # the skin's code, loaded only when a skin is asked
    from ..skin.measure import body_measurements, mesh_measurements
    from ..skin.surface import build_skin

    if measured is None:  # a mannequin already made: its skin made again, as its file records
        report(0.0, f"making the skin ({settings.voxel_mm:g} mm voxels)")
        return mannequin, measured, SkinMade(build_skin(mannequin, settings), {}, False)
    if job.options.mode == "exact":
        report(0.0, f"refining the pieces until their skin measures the request ({settings.voxel_mm:g} mm voxels)")
        made = exact_skin(mannequin, settings, job.five, dict(job.extra) or None)
        measured = {**measured, **made.pieces_measured}
        skin = SkinMade(made.skin, dict(made.skin_measured), True, made.rounds, made.converged)
        return made.mannequin, measured, skin
    report(0.0, f"making the skin ({settings.voxel_mm:g} mm voxels)")
    skin = build_skin(mannequin, settings)
    on_mesh = mesh_measurements(skin)
    if job.extra:
        values = body_measurements(skin).values
        on_mesh.update({key: values.get(key, float("nan")) for key in EXTRA_MEASUREMENTS if key in job.extra})
    return mannequin, measured, SkinMade(skin, on_mesh, False)


def pose_frames(source, mannequin):
    """(frames, warnings, notes) of a pose source (``core.job.request.PoseSource``) on ``mannequin``: a clip
    retargeted onto its joints and clamped to their ranges (warnings: what was clamped; notes: where the feet
    went), a pose file's frames or a standard pose made on its joints; ElliMannError naming the joint (and frame) of
    a pose beyond the limits (a clip's are clamped)."""
    from ..pose.kinematics import check_limits, require_joints
    from ..pose.standard import standard_motion

    if source.clip is not None:
        from ..pose.clip import clip_onto

        clip = source.clip
        onto = clip_onto(mannequin, clip.motion, clip.match, source.ask.keep_on_floor, clip.name)
        hint = "" if source.ask.keep_on_floor else source.ask.floor_hint
        return onto.poses, onto.clamp_lines(), [onto.floor_line(hint)]
    joints = require_joints(mannequin)
    frames = source.frames if source.frames is not None else standard_motion(source.name, joints, source.fps)
    for index, frame in enumerate(frames):
        check_limits(frame, joints, index if len(frames) > 1 else None)
    return frames, [], []
