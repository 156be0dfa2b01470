"""What a user can ask of ElliMann in one job, checked whole before any work starts.

A :class:`Request` holds everything: the five measurements and any extra ones (cm), the reference set, the
synthesis options, cushions, the skin and its settings, a pose (a standard pose, a pose file or a BVH clip) and the
files to write; or, instead of measurements, a mannequin already made (``pose IN.json``). :func:`check` turns it
into a :class:`Job` or refuses it in one line (ElliMannError): a request out of its limits, extra measurements that
contradict the five, a path whose format is unknown or needs Blender where there is none, an animation for a format
that holds none, a pose without joints, a skin voxel too fine for memory or too coarse for a piece, an avatar (the
format table's FBX row) without a skin, joints or a rest pose it can stand in. Nothing is made, let alone written,
for a request that would be refused halfway. ``synth``, ``pose``, ``sizes``, every row of ``batch`` and the
Synthesize operator build their jobs here; ``core.job.make`` makes them.
"""

from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import ElliMannError
from ..formats.table import check_outputs
from ..measure.tailor import as_dict
from ..measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ..settings import AVATAR_POSES
from ..synthesis.extra_refine import ExtraRequestError, extra_request_problems
from ..synthesis.options import SynthesisOptions
from ..synthesis.request import checked_request


class NeedsBlenderError(ElliMannError):
    """A job with an output (``path``, of format ``kind``) only Blender writes, where Blender is not available."""

    def __init__(self, path, kind):
        super().__init__(f"writing {path} needs Blender: the bpy module is not installed")
        self.path, self.kind = path, kind


@dataclass(frozen=True)
class PoseAsk:
    """A pose as asked: a standard pose's name, a pose .json or a BVH clip (``source``), its frames per second
    (``fps``; None: the walk's default, or a clip's own rate), whose bone names a clip uses (``rig``) and whether a
    clip's lowest foot is held on the floor (``floor_hint``: how the caller's user asks that, said where a clip's
    feet leave the floor)."""

    source: str
    fps: float | None = None
    rig: str = "auto"
    keep_on_floor: bool = False
    floor_hint: str = ""


@dataclass(frozen=True)
class Request:
    """One mannequin as a user asks for it. ``measurements``: the five {He, Sh, Br, Wa, Hi: cm}; ``extra``: any of
    the extra measurements {key: cm}; ``references``: a loaded ``core.synthesis.reference_set.ReferenceSet``;
    ``skin``: a ``core.skin.settings.SkinSettings`` (None: no skin); ``outputs``: the paths to write (formats by
    their extensions, ``core.formats.table``). ``mannequin``: one already made, posed (and skinned) as it is,
    instead of one synthesized from measurements. ``avatar``: how an avatar output (.fbx) is written
    (``core.formats.avatar.AvatarOptions``; None: its defaults), its rest pose the request's ``pose`` when one is
    asked."""

    measurements: dict | None = None
    references: object = None
    extra: dict = field(default_factory=dict)
    options: SynthesisOptions = field(default_factory=SynthesisOptions)
    cushions: bool = False
    skin: object = None
    pose: PoseAsk | None = None
    outputs: tuple = ()
    mannequin: object = None
    avatar: object = None


@dataclass(frozen=True)
class PoseSource:
    """A pose ask read: the frames of a pose file, or the clip of a .bvh (``core.formats.bvh.BvhClip``), or neither
    (a standard pose), its frames per second and whether it moves (more than one frame)."""

    ask: PoseAsk
    fps: float
    frames: list | None = None
    clip: object = None
    animated: bool = False

    @property
    def name(self):
        return self.ask.source


@dataclass
class Job:
    """A checked :class:`Request`: the five as a (5,) array in MEASUREMENTS order (None for a mannequin already
    made), the extra ones in EXTRA_MEASUREMENTS order, the range warnings, the pose's source read and each output
    path's format (its row of ``core.formats.table``, decided here once)."""

    request: Request
    values: object
    extra: dict
    warnings: list
    pose: PoseSource | None
    formats: dict  # {path: Format}
    skin: object = None  # the SkinSettings asked, its kind decided ("auto" -> "body" or "pieces")
    skin_reference: object = None  # the set whose bodies a body skin is made from (a made mannequin's: by its name)
    avatar: object = None  # an avatar output's AvatarOptions, its pose decided (None: the job writes no avatar)

    @property
    def reference(self):
        return self.request.references

    @property
    def options(self):
        return self.request.options

    @property
    def five(self):
        return None if self.values is None else as_dict(self.values)

    def needs_blender(self):
        """The first output that needs Blender to be written (posed as asked), or None."""
        posed = self.pose is not None
        return next((path for path, kind in self.formats.items() if kind.needs_blender_for(posed)), None)


def check(request, blender=True, pose=None):
    """The :class:`Job` of ``request``, or ElliMannError (one line) for anything that would refuse it later;
    ``blender``: whether Blender's writers can run here (a .blend or .glb output is refused without them);
    ``pose``: the request's pose already read (a batch reads it once for every row), else read here."""
    request.options.checked()
    made = request.mannequin
    if made is None:
        reference = request.references
        values, warnings = checked_request(request.measurements, reference.ranges, reference.absurd_limits)
        extra = checked_extra(as_dict(values), request.extra)
    else:
        values, warnings, extra = None, [], {}
    pose = read_pose_ask(request.pose) if pose is None else pose
    formats = check_outputs(request.outputs, pose.name if pose is not None and pose.animated else None)
    job = Job(request, values, extra, warnings, pose, formats)
    needs = job.needs_blender()
    if needs is not None and not blender:
        raise NeedsBlenderError(needs, formats[needs])
    if pose is not None:
        if made is not None and made.joints is None:
            raise ElliMannError(
                f"joints: '{made.name}' has no joints (a file from before posing, or a collection without a "
                f"skeleton), so neither it{' nor its skin' if request.skin is not None else ''} can be posed: "
                "synthesize it again or load a Reference Mannequin"
            )
        if made is None and request.references.joints is None:
            raise ElliMannError(
                f"joints: the {request.references.name} set's Reference Mannequins have none, so its mannequins "
                "cannot be posed: synthesize from a set with joints (the shipped sets have them)"
            )
    if request.skin is not None:
        job.skin, job.skin_reference = checked_skin(request)
    job.avatar = checked_avatar(request, formats, pose)
    return job


def checked_avatar(request, formats, pose):
    """The AvatarOptions of a request writing an avatar (a row of the format table that ``needs_skin``: .fbx), its
    rest pose the request's pose when one is asked; None when it writes none. ElliMannError (one line) naming the
    file for an avatar without a skin, without joints, or asked to stand in a pose that is not a rest pose."""
    path = next((path for path, kind in formats.items() if kind.needs_skin), None)
    if path is None:
        return None
    from ..formats.avatar import AvatarOptions  # the avatar's code, loaded only when one is written

    if request.skin is None:
        raise ElliMannError(f"{path}: an FBX avatar is the mannequin's skin on its bones: ask for a skin (--skin)")
    made = request.mannequin
    joints = made.joints if made is not None else request.references.joints
    if joints is None:
        raise ElliMannError(f"{path}: an FBX avatar needs a skeleton, and this mannequin has no joints")
    avatar = request.avatar or AvatarOptions()
    if pose is not None:
        if pose.clip is not None or pose.frames is not None or pose.name not in AVATAR_POSES:
            poses = " or ".join(AVATAR_POSES)
            raise ElliMannError(
                f"{path}: an FBX avatar stands in its rest pose, {poses}, not {pose.name!r}; write that pose to "
                "another format"
            )
        avatar = replace(avatar, pose=pose.name)
    return avatar.checked()


def checked_skin(request):
    """(the skin's settings, its kind decided, and the set a body skin is made from) of a request asking one; SkinError
    or ElliMannError (one line) for a skin that would be refused: a body skin from a set without bodies, a voxel too
    fine for memory or too coarse for a piece of the pieces' skin."""
    settings, made = request.skin, request.mannequin
    reference = request.references
    if made is not None:  # its file's record says which (a body skin remade from its set, known by its name)
        recorded = (made.skin or {}).get("kind", "pieces")
        kind = recorded if settings.kind == "auto" else settings.kind
        if kind == "body":
            from ..synthesis.shipped import named_reference_set

            reference = named_reference_set(made.reference_set)
    else:
        kind = settings.kind
    bodies = reference is not None and reference.manifest is not None and reference.manifest.bodies is not None
    if kind == "auto":
        kind = "body" if bodies else "pieces"
    if kind == "body" and not bodies:
        whose = f"the {reference.name} set" if reference is not None else "its set"
        raise ElliMannError(
            f"skin_kind: {whose} has no bodies (a set from before sets kept their bodies, or a hand-traced one): "
            "the skin over its pieces can be made (skin kind pieces)"
        )
    settings = settings.of_kind(kind)
    if kind == "pieces":
        from ..skin.surface import check_skin  # the skin's code, loaded only when a skin is asked

        for mannequin in [made] if made is not None else reference.mannequins:
            check_skin(mannequin, settings)
    return settings, reference if kind == "body" else None


def row_job(command, measurements, references, extra, warnings, name, outputs):
    """The job of one row of a batch: the ``command``'s (checked whole once by :func:`check`) with the row's
    ``measurements`` (the five, cm), ``extra`` ones and their range ``warnings`` (checked where the row was read),
    its reference set, its mannequin's ``name`` and its ``outputs`` (their formats decided here). A row writing no
    file of its own (a batch file's only) is not posed."""
    request = replace(
        command.request,
        measurements=measurements,
        references=references,
        extra=extra,
        options=command.options.replace(name=name),
        outputs=tuple(outputs),
    )
    pose = command.pose if outputs else None
    values = np.array([measurements[key] for key in MEASUREMENTS], dtype=float)
    extra = {key: float(extra[key]) for key in EXTRA_MEASUREMENTS if key in extra}
    formats = check_outputs(outputs, pose.name if pose is not None and pose.animated else None)
    skin_reference = references if command.skin is not None and command.skin.kind == "body" else None
    return Job(request, values, extra, list(warnings), pose, formats, command.skin, skin_reference, command.avatar)


def checked_extra(five, extra):
    """The extra measurements asked, as floats in EXTRA_MEASUREMENTS order; ExtraRequestError (one line) for one
    that is not a measurement, out of its limits or contradicting the five."""
    unknown = [key for key in extra if key not in EXTRA_MEASUREMENTS]
    if unknown:
        raise ExtraRequestError(f"{unknown[0]}: not a measurement (one of {', '.join(EXTRA_MEASUREMENTS)})")
    problems = extra_request_problems(five, extra)
    if problems:
        raise ExtraRequestError(problems[0])
    return {key: float(extra[key]) for key in EXTRA_MEASUREMENTS if key in extra}


def read_pose_ask(ask):
    """The :class:`PoseSource` of a PoseAsk (None for None): a .bvh clip read (its bones matched by ``ask.rig``), a
    pose .json read, or a standard pose's name checked. ElliMannError naming the file or the name."""
    if ask is None:
        return None
    from ..pose.standard import MOTIONS, WALK_FPS, check_pose_name

    lowered = ask.source.lower()
    if lowered.endswith(".bvh"):
        from ..formats.bvh import read_bvh

        clip = read_bvh(ask.source, ask.rig, ask.fps)
        return PoseSource(ask, clip.motion.fps, clip=clip, animated=clip.motion.frames > 1)
    fps = WALK_FPS if ask.fps is None else ask.fps
    if lowered.endswith(".json"):
        from ..formats.posed_files import read_pose

        frames = read_pose(ask.source)
        return PoseSource(ask, fps, frames=frames, animated=len(frames) > 1)
    check_pose_name(ask.source)
    return PoseSource(ask, fps, animated=ask.source in MOTIONS)
