"""BVH motion-capture clips read with numpy alone: the HIERARCHY (bones, offsets, channels, end sites), the MOTION
(one line of channel values per frame), the units the offsets are in, and the clip in ElliMann's axes as a
``core.pose.retarget.SourceMotion`` with the bones matched to the mannequin's joints (``core.pose.bone_match``).

The conventions are those of Blender's own importer (``import_anim.bvh``), which the tests compare against: every
bone rests with the world's axes; its rotation channels, in the order listed, give R = R1(a1) R2(a2) R3(a3)
(degrees); a bone with position channels has its head there (a channel it lacks is 0), relative to its parent, the
root's in the world; the file is Y up with the character facing +Z (ElliMann: Z up, facing -Y). The units are the
one of metres, centimetres, millimetres, inches and the CMU database's (1/0.45 inch) that makes the rest skeleton
stand nearest 1.7 m. A file that is not such a clip is refused in one line naming the line, before anything is
computed, and so is a clip too long for the memory there is (estimated from its header).
"""

import os
from dataclasses import dataclass

import numpy as np

from ..errors import ElliMannError
from ..pose.bone_match import AUTO, match_bones
from ..pose.retarget import SourceMotion, check_fps, resample

TO_ELLIMANN = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # BVH's +Z (front) is ElliMann's -Y
UNITS = (
    ("metres", 1.0),
    ("centimetres", 0.01),
    ("millimetres", 0.001),
    ("inches", 0.0254),
    ("CMU units (1/0.45 inch)", 0.0254 / 0.45),
)
STANDING_HEIGHT = 1.7  # m: the units are those that make the rest skeleton nearest this tall
MEMORY_SHARE = 0.5  # of the memory available, at most this much for one clip
CHUNK = 4096  # frame lines converted at a time
_AXES = {"x": 0, "y": 1, "z": 2}


BASE_BYTES = 150e6  # what writing a posed file takes whatever its length (the MJCF's mass by Monte Carlo: 113 MB)
FRAME_BYTES = 24_000  # per frame written: the joints' arrays, the poses and a .json's text (measured: 23 KB)


def bytes_needed(frames, channels, bones, output_frames=None):
    """An estimate (bytes) of what reading a clip, retargeting it and writing it takes: its values, its bones'
    rotations and heads (a few copies while they are computed), then per frame written the mannequin's joints'
    arrays, their poses and a file's text, over a fixed base (measured with tracemalloc: bench/bench_bvh.py)."""
    output_frames = frames if output_frames is None else output_frames
    return int(BASE_BYTES + frames * (8 * channels + 400 * bones) + output_frames * FRAME_BYTES)


def memory_available():
    """Bytes of memory available now (Linux: MemAvailable; elsewhere the free pages), or None if unknown."""
    try:
        with open("/proc/meminfo", encoding="ascii") as stream:
            for line in stream:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


@dataclass
class Bone:
    name: str
    parent: int
    offset: np.ndarray  # (3,) file units, BVH axes
    rotation: list  # [(axis 0-2, column)] in channel order
    position: list  # [(axis 0-2, column)]
    end: np.ndarray = None  # an End Site's offset, if any


@dataclass
class BvhClip:
    """A BVH file read: the motion (ElliMann's axes, metres), its bones matched to the joints, and what it said."""

    path: str
    motion: SourceMotion
    match: object  # core.pose.bone_match.BoneMatch
    units: str
    unit: float  # metres per file unit
    height: float  # the rest skeleton's height in file units
    file_frames: int
    file_fps: float

    @property
    def name(self):
        return os.path.basename(self.path)

    def lines(self):
        """What was read and matched, a line each."""
        rate = f"{self.motion.fps:.4g} fps"
        if self.motion.frames != self.file_frames or abs(self.motion.fps - self.file_fps) > 1e-9:
            rate += f" (resampled from {self.file_frames} frames at {self.file_fps:.4g} fps)"
        return [
            f"{self.name}: {self.motion.frames} frames at {rate}, {len(self.motion.names)} bones, units: "
            f"{self.units} (the rest skeleton stands {self.height:.4g} high: {self.height * self.unit:.2f} m)",
            *self.match.lines(),
        ]


def read_bvh(path, rig=AUTO, fps=None, memory=None):
    """The BvhClip of the file at ``path``: ``rig`` forces a bone-name map (``core.pose.bone_match``), ``fps``
    resamples (None: the clip's rate), ``memory``: bytes available (None: what the machine has now).
    ElliMannError in one line, naming the file and the line, for anything that is not a clip ElliMann can use."""
    path = os.fspath(path)
    name = os.path.basename(path)
    if fps is not None:
        check_fps(fps)
    try:
        with open(path, "rb") as stream:
            bones, frames, frame_time, first_line = _hierarchy(stream, name)
            channels = sum(len(b.rotation) + len(b.position) for b in bones)
            output_frames = frames if fps is None else int(frames * frame_time * fps) + 1
            _check_size(path, name, stream.tell(), frames, channels, len(bones), output_frames, memory)
            values = _motion(stream, name, frames, channels, first_line)
    except OSError as error:
        raise ElliMannError(f"clip: cannot read {path}: {error.strerror or error}") from None
    height, unit, units = _units(bones, name)
    match = match_bones([b.name for b in bones], [b.parent for b in bones], rig, name)
    motion = _motion_of(bones, values, unit, 1.0 / frame_time)
    resampled = motion if fps is None else resample(motion, fps)
    return BvhClip(path, resampled, match, units, unit, height, frames, 1.0 / frame_time)


def _words(stream):
    """(word or bone name, line number) of the HIERARCHY up to MOTION's frame time line; a bone's name is what
    follows ROOT / JOINT on its line. Read line by line, so the stream stops after the frame time line."""
    number = 0
    while line := stream.readline():
        number += 1
        words = line.decode("utf-8", "replace").split()
        if words and words[0].upper() in ("ROOT", "JOINT"):
            rest = words[1:-1] if len(words) > 2 and words[-1] == "{" else words[1:]
            yield words[0].upper(), number
            yield " ".join(rest), number
            if len(rest) < len(words) - 1:
                yield "{", number
            continue
        for word in words:
            yield word, number
        if len(words) >= 3 and words[0].lower() == "frame" and words[1].lower() == "time:":
            return


def _hierarchy(stream, name):
    words = _words(stream)
    last = [0]

    def take(what):
        try:
            word, last[0] = next(words)
        except StopIteration:
            raise ElliMannError(f"clip {name}: ends at line {last[0]} where {what} should follow") from None
        return word

    def number(what):
        word = take(what)
        try:
            value = float(word)
        except ValueError:
            value = float("nan")
        if not np.isfinite(value):
            raise ElliMannError(f"clip {name}, line {last[0]}: {what} must be a finite number, got {word[:20]!r}")
        return value

    def expect(keyword):
        word = take(keyword)
        if word.upper() != keyword.upper():
            raise ElliMannError(f"clip {name}, line {last[0]}: expected {keyword}, got {word[:20]!r}")

    if take("HIERARCHY").upper() != "HIERARCHY":
        raise ElliMannError(f"clip {name}: is not a BVH clip (its first word is not HIERARCHY)")
    bones, stack, names, column = [], [], set(), 0
    while True:
        word = take("a bone, }, or MOTION")
        upper = word.upper()
        if upper in ("ROOT", "JOINT"):
            bone_name = take("a bone's name")
            if not bone_name or (upper == "JOINT") != bool(stack):
                where = "inside a bone" if stack else "outside any ROOT"
                raise ElliMannError(f"clip {name}, line {last[0]}: {upper} {bone_name!r} {where}")
            unique, repeat = bone_name, 0
            while unique in names:  # as Blender's importer does with a repeated name
                repeat += 1
                unique = f"{bone_name}.{repeat:03d}"
            names.add(unique)
            expect("{")
            expect("OFFSET")
            offset = np.array([number("OFFSET's x"), number("OFFSET's y"), number("OFFSET's z")])
            expect("CHANNELS")
            count = number("the number of CHANNELS")
            if count != int(count) or not 0 <= count <= 6:
                raise ElliMannError(f"clip {name}, line {last[0]}: CHANNELS must be 0 to 6, got {count:g}")
            rotation, position, seen = [], [], set()
            for _ in range(int(count)):
                channel = take("a channel name").lower()
                axis, kind = channel[:1], channel[1:]
                if axis not in _AXES or kind not in ("position", "rotation") or channel in seen:
                    what = "repeats" if channel in seen else "is not one of"
                    raise ElliMannError(
                        f"clip {name}, line {last[0]}: channel {channel!r} of {bone_name!r} {what} X/Y/Z position "
                        f"and X/Y/Z rotation"
                    )
                seen.add(channel)
                (rotation if kind == "rotation" else position).append((_AXES[axis], column))
                column += 1
            bones.append(Bone(unique, stack[-1] if stack else -1, offset, rotation, position))
            stack.append(len(bones) - 1)
        elif upper == "END":
            expect("Site")
            expect("{")
            expect("OFFSET")
            end = np.array([number("OFFSET's x"), number("OFFSET's y"), number("OFFSET's z")])
            expect("}")
            if not stack:
                raise ElliMannError(f"clip {name}, line {last[0]}: End Site outside any bone")
            bones[stack[-1]].end = end
        elif word == "}" and stack:
            stack.pop()
        elif upper == "MOTION" and not stack and bones:
            break
        else:
            raise ElliMannError(f"clip {name}, line {last[0]}: unexpected {word[:20]!r} in the HIERARCHY")
    expect("Frames:")
    frames = number("the number of Frames")
    if frames != int(frames) or frames < 1:
        raise ElliMannError(f"clip {name}, line {last[0]}: Frames must be a whole number of at least 1, got {frames:g}")
    expect("Frame")
    expect("Time:")
    frame_time = number("Frame Time")
    if not frame_time > 0:
        raise ElliMannError(f"clip {name}, line {last[0]}: Frame Time must be positive, got {frame_time:g}")
    return bones, int(frames), frame_time, last[0] + 1


def _check_size(path, name, header_end, frames, channels, bones, output_frames, memory):
    """Refuse a clip whose file is too short for its frames, or whose work would not fit in memory."""
    rest = os.path.getsize(path) - header_end
    if channels and rest < frames * channels * 2 - 1:  # every value takes a digit and a separator
        raise ElliMannError(
            f"clip {name}: is truncated: its {frames} frames of {channels} values need at least "
            f"{frames * channels * 2 - 1} more bytes, the file has {max(rest, 0)}"
        )
    available = memory_available() if memory is None else memory
    needed = bytes_needed(frames, channels, bones, output_frames)
    if available is not None and needed > MEMORY_SHARE * available:
        raise ElliMannError(
            f"clip {name}: {frames} frames of {bones} bones need about {needed / 1e9:.1f} GB to retarget, more than "
            f"half the {available / 1e9:.1f} GB of memory available; cut the clip or resample it (--fps)"
        )


def _motion(stream, name, frames, channels, first_line):
    """(frames, channels) values of the frame lines (blank lines skipped)."""
    values = np.empty((frames, channels))
    chunk, numbers, row = [], [], 0
    for number, line in enumerate(stream, start=first_line):
        words = line.decode("utf-8", "replace").split()
        if not words:
            continue
        if row + len(chunk) >= frames:
            raise ElliMannError(f"clip {name}, line {number}: more frame lines than its Frames: {frames}")
        if len(words) != channels:
            raise ElliMannError(
                f"clip {name}, line {number}: frame {row + len(chunk) + 1} has {len(words)} values, its bones' "
                f"channels are {channels}"
            )
        chunk.append(words)
        numbers.append(number)
        if len(chunk) == CHUNK:
            row = _convert(values, row, chunk, numbers, name)
            chunk, numbers = [], []
    row = _convert(values, row, chunk, numbers, name)
    if row < frames:
        raise ElliMannError(f"clip {name}: is truncated: its MOTION has {row} frame lines of the {frames} it announces")
    return values


def _convert(values, row, chunk, numbers, name):
    if not chunk:
        return row
    try:
        block = np.array(chunk, dtype=float)
    except ValueError:
        block = None
    if block is None or not np.all(np.isfinite(block)):
        for words, number in zip(chunk, numbers):
            for word in words:
                try:
                    good = np.isfinite(float(word))
                except ValueError:
                    good = False
                if not good:
                    raise ElliMannError(f"clip {name}, line {number}: {word[:20]!r} is not a finite number")
    values[row : row + len(chunk)] = block
    return row + len(chunk)


def _units(bones, name):
    """(rest height in file units, metres per unit, the units' name) from the rest skeleton's offsets."""
    heads = _rest_heads(bones)
    ends = np.array([h + b.end for h, b in zip(heads, bones) if b.end is not None]).reshape(-1, 3)
    points = np.vstack([heads, ends])
    extent = points.max(axis=0) - points.min(axis=0)
    height = float(extent[1])
    if not height > 0 or height < 0.5 * max(extent[0], extent[2]):
        raise ElliMannError(
            f"clip {name}: its rest skeleton does not stand up along Y, BVH's up axis (it spans {extent[0]:.4g} "
            f"along X, {extent[1]:.4g} along Y, {extent[2]:.4g} along Z)"
        )
    label, unit = min(UNITS, key=lambda u: abs(np.log(height * u[1] / STANDING_HEIGHT)))
    return height, unit, label


def _rest_heads(bones):
    heads = np.zeros((len(bones), 3))
    for i, bone in enumerate(bones):
        heads[i] = bone.offset + (heads[bone.parent] if bone.parent >= 0 else 0.0)
    return heads


def _axis_rotations(axis, degrees):
    angle = np.radians(degrees)
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros(angle.shape + (3, 3))
    i, j = (axis + 1) % 3, (axis + 2) % 3
    out[..., axis, axis] = 1.0
    out[..., i, i], out[..., j, j] = c, c
    out[..., j, i], out[..., i, j] = s, -s
    return out


def _motion_of(bones, values, unit, fps):
    """The SourceMotion of the bones' channel values: forward kinematics in BVH's axes, then ElliMann's."""
    frames = len(values)
    world = np.empty((frames, len(bones), 3, 3))
    heads = np.empty((frames, len(bones), 3))
    for i, bone in enumerate(bones):
        local = np.broadcast_to(np.eye(3), (frames, 3, 3))
        for axis, column in bone.rotation:
            local = local @ _axis_rotations(axis, values[:, column])
        offset = np.broadcast_to(bone.offset, (frames, 3))
        if bone.position:
            offset = np.zeros((frames, 3))
            for axis, column in bone.position:
                offset[:, axis] = values[:, column]
        if bone.parent < 0:
            world[:, i], heads[:, i] = local, offset
        else:
            parent = world[:, bone.parent]
            world[:, i] = parent @ local
            heads[:, i] = heads[:, bone.parent] + np.einsum("fij,fj->fi", parent, offset)
    rest = _rest_heads(bones)
    ends = [h + b.end for h, b in zip(rest, bones) if b.end is not None]
    lowest = min(float(np.min(rest[:, 1])), *(float(e[1]) for e in ends)) if ends else float(np.min(rest[:, 1]))
    moving = [i for i, b in enumerate(bones) if b.parent < 0 and b.position]
    return SourceMotion(
        names=[b.name for b in bones],
        parents=[b.parent for b in bones],
        rest_heads=unit * rest @ TO_ELLIMANN.T,
        rotations=TO_ELLIMANN @ world @ TO_ELLIMANN.T,
        positions=unit * heads @ TO_ELLIMANN.T,
        fps=fps,
        rest_floor=unit * lowest,
        floor=0.0 if moving else unit * lowest,
    )
