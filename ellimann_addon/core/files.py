"""Atomic file writing: a crash or a full disk never leaves a half-written file behind.

A file is written to a temporary name in its folder, checked to be whole (:func:`incomplete`) and
only then renamed onto its target. Temporary names are ``.ellimann-PID@HOST-XXXXXXXX.tmp`` (files)
and ``.ellimann-PID@HOST-XXXXXXXX/`` (the folders Blender writes into, :func:`atomic_output`), so
:func:`clean_stale_temporaries` can tell what a killed run left from what a running one is writing.
"""

import contextlib
import errno
import json
import os
import re
import shutil
import socket
import struct
import tempfile
import time
import xml.etree.ElementTree as ElementTree

TEMP_PREFIX = ".ellimann-"
STALE_AGE = 3600.0  # s: a temporary of another machine (or of an older ElliMann) untouched this long is stale


def atomic_write_bytes(path, data):
    """Write ``data`` to ``path`` via a temporary file in the same folder and an atomic rename.

    The temporary file is read back before the rename (its size, and for .json/.xml that it parses), so
    a write that the file system cut short raises OSError (``filename`` = ``path``) and leaves the target as it was.
    """
    atomic_write_stream(path, lambda stream: stream.write(data))


def atomic_write_stream(path, write):
    """:func:`atomic_write_bytes` of what ``write(stream)`` writes into a binary file stream, piece by piece (a
    file larger than memory): the temporary file is checked to hold every byte written, and to be whole."""
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    handle, temp = tempfile.mkstemp(prefix=temp_prefix(), suffix=".tmp", dir=folder)
    try:
        with os.fdopen(handle, "wb") as stream:
            write(stream)
            written = stream.tell()
            stream.flush()
            os.fsync(stream.fileno())
        problem = (
            f"{os.path.getsize(temp)} of {written} bytes reached the disk"
            if os.path.getsize(temp) != written
            else incomplete(temp, extension_of(path))
        )
        if problem:
            raise OSError(errno.EIO, f"the file written is incomplete: {problem}", path)
        os.chmod(temp, 0o666 & ~_umask())  # mkstemp makes 0600; give the file the usual permissions
        os.replace(temp, path)
    except BaseException:
        if os.path.exists(temp):
            os.unlink(temp)
        raise


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write_text(path, text):
    atomic_write_bytes(path, text.encode("utf-8"))


# ------------------------------------------------------------------------------------------------ whole files


def extension_of(path):
    """A path's extension, lower case, without the dot ("" if none): the file kind :func:`incomplete` checks
    ("blend", "glb", "json", …) and the format ``core.formats.table.format_of`` names."""
    return os.path.splitext(os.fspath(path))[1].lower().lstrip(".")


def incomplete(path, kind=None):
    """Why the file at ``path`` is not whole (a short reason), or None if it is.

    Cheap checks of the end of the file, where a write cut short (full disk) shows: .blend: the
    block chain from the header to the ENDB block (Blender 4.x and 5.x layouts; zstd files: the
    frames listed in the seek table Blender appends; gzip: the decompressed blocks); .glb: the
    length in the header is the file's and the chunks fill it; .json/.xml: it parses; .png: it
    ends with IEND; .obj and .csv: it ends with a complete line; .npz: its zip directory reads; .fbx (binary): its
    signature and its footer; .vit: it parses as XML. Any other kind: it is not empty.
    """
    kind = extension_of(path) if kind is None else kind
    try:
        size = os.path.getsize(path)
        if not size:
            return "it is empty"
        with open(path, "rb") as stream:
            check = _CHECKS.get(kind)
            return check(stream, size) if check else None
    except OSError as error:
        return error.strerror or str(error)


def _blend(stream, size):
    magic = stream.read(4)
    stream.seek(0)
    if magic == b"\x28\xb5\x2f\xfd":
        return _zstd_seekable(stream, size)
    if magic[:2] == b"\x1f\x8b":
        import gzip

        try:
            return _blend_blocks(gzip.GzipFile(fileobj=stream))
        except (OSError, EOFError) as error:
            return f"its gzip data is cut short ({error})"
    return _blend_blocks(stream)


def _blend_blocks(stream):
    """Walk the blocks of an uncompressed .blend: 4.x ``BLENDER-v402`` (12-byte header, 20/24-byte block
    headers with a 32-bit length) or 5.x ``BLENDER17-01v0500`` (header size in the header, 32-byte block
    headers with a 64-bit length); the last block must be ENDB."""
    header = stream.read(17)
    if header[:7] != b"BLENDER":
        return "it does not start with a .blend header"
    if header[7:8] in (b"_", b"-"):  # 4.x: pointer size, endianness, version
        order = "<" if header[8:9] == b"v" else ">"
        start, head = 12, struct.Struct(f"{order}4si{'I' if header[7:8] == b'_' else 'Q'}ii")
        length_of = 1
    elif header[7:9].isdigit():  # 5.x: header size, "-", file format version, endianness, version
        start = int(header[7:9])
        order = "<" if header[12:13] == b"v" else ">"
        head, length_of = struct.Struct(f"{order}4siQqq"), 3
    else:
        return "its .blend header is not one Blender writes"
    position = start
    while True:
        stream.seek(position)
        data = stream.read(head.size)
        if len(data) < head.size:
            return f"it ends before its ENDB block (after {position} bytes)"
        fields = head.unpack(data)
        if fields[0] == b"ENDB":
            return None
        if fields[length_of] < 0:
            return f"a block at byte {position} has a negative length"
        position += head.size + fields[length_of]


def _zstd_seekable(stream, size):
    """Blender writes zstd .blend files in the seekable format: frames, then a skippable frame whose
    footer counts them; the frames' sizes plus the table must be the file's size."""
    if size < 17:
        return "it is too short for a zstd .blend"
    stream.seek(size - 9)
    frames, descriptor, magic = struct.unpack("<IBI", stream.read(9))
    if magic != 0x8F92EAB1:
        return "its zstd seek table is missing: the file is cut short"
    entry = 12 if descriptor & 0x80 else 8
    table = frames * entry + 9
    if table + 8 > size:
        return "its zstd seek table is larger than the file"
    stream.seek(size - 8 - table)
    skippable, length = struct.unpack("<II", stream.read(8))
    if skippable != 0x184D2A5E or length != table:
        return "its zstd seek table does not start where its footer says"
    entries = stream.read(frames * entry)
    total = sum(struct.unpack_from("<I", entries, i * entry)[0] for i in range(frames))
    if total + table + 8 != size:
        return f"its zstd frames add up to {total + table + 8} bytes, not {size}"
    position = 0
    for i in range(frames):  # every frame starts with the zstd magic
        stream.seek(position)
        if stream.read(4) != b"\x28\xb5\x2f\xfd":
            return f"its zstd frame {i + 1} is damaged"
        position += struct.unpack_from("<I", entries, i * entry)[0]
    return None


def _glb(stream, size):
    header = stream.read(12)
    if len(header) < 12 or header[:4] != b"glTF":
        return "it does not start with a binary glTF header"
    length = struct.unpack_from("<I", header, 8)[0]
    if length != size:
        return f"its header says {length} bytes, the file has {size}"
    position = 12
    while position < size:
        stream.seek(position)
        chunk = stream.read(8)
        if len(chunk) < 8:
            return f"a chunk header at byte {position} is cut short"
        position += 8 + struct.unpack_from("<I", chunk)[0]
    return None if position == size else f"its last chunk runs past the end ({position} of {size} bytes)"


def _json(stream, size):
    try:
        json.loads(stream.read().decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as error:
        return f"it is not valid JSON ({error})"
    return None


def _xml(stream, size):
    try:
        ElementTree.parse(stream)
    except ElementTree.ParseError as error:
        return f"it is not valid XML ({error})"
    return None


def _png(stream, size):
    if stream.read(8) != b"\x89PNG\r\n\x1a\n":
        return "it does not start with a PNG signature"
    stream.seek(max(size - 12, 0))
    return None if stream.read(12)[4:8] == b"IEND" else "it does not end with an IEND chunk"


def _obj(stream, size):
    stream.seek(max(size - 1, 0))
    return None if stream.read(1) == b"\n" else "it does not end with a complete line"


def _npz(stream, size):
    import zipfile

    try:
        zipfile.ZipFile(stream).close()  # reads the central directory at the end of the file
    except (zipfile.BadZipFile, OSError, EOFError) as error:
        return f"its zip directory cannot be read ({error})"
    return None


FBX_MAGIC = b"Kaydara FBX Binary  \x00"
FBX_FOOTER = bytes.fromhex("f85a8c6adef5d97eece90ce3758f290b")  # the last 16 bytes of a binary FBX file


def _fbx(stream, size):
    if stream.read(len(FBX_MAGIC)) != FBX_MAGIC:
        return "it does not start with the binary FBX signature"
    stream.seek(max(size - len(FBX_FOOTER), 0))
    return None if stream.read(len(FBX_FOOTER)) == FBX_FOOTER else "it does not end with the FBX footer"


_CHECKS = {"blend": _blend, "glb": _glb, "json": _json, "xml": _xml, "png": _png, "obj": _obj, "npz": _npz}
_CHECKS["fbx"] = _fbx
_CHECKS["vit"] = _xml  # a Seamly2D / Valentina measurements file (core.sizing.writers) is XML
_CHECKS["csv"] = _obj  # a size chart's row (core.sizing.writers): it ends with a complete line, as an .obj
CHECKED_KINDS = tuple(_CHECKS)  # the extensions :func:`incomplete` checks beyond "not empty"


def disk_full(folder):
    """True if no more bytes can be written in ``folder`` (statvfs; False where it is not available)."""
    try:
        info = os.statvfs(folder)
    except (AttributeError, OSError):
        return False
    free = info.f_bfree if hasattr(os, "geteuid") and os.geteuid() == 0 else info.f_bavail
    return free == 0


# ------------------------------------------------------------------------------------------------ reading


# What a file ElliMann reads whole (a mannequin .json, a pose file, a .glb's JSON) may weigh: a 90-piece mannequin with
# its traces is 0.13 MB, a posed clip 2.8 kB a frame (35,000 frames, 20 minutes at 30 fps, fit). Parsing JSON takes
# about ten times the file in memory and Python objects, so a larger file is refused before it is read (a 300 MB file
# of a million ellipsoids took 20 s and 2.8 GB to refuse after parsing).
MAX_READ_BYTES = 100 * 1000**2


class TooLargeError(ValueError):
    """A file refused for its size before it was read (the message names the file, its size and the limit)."""


def read_bytes_within(path, limit=MAX_READ_BYTES, what="a file ElliMann reads whole"):
    """The bytes of ``path``; TooLargeError, before a byte is read, if the file is larger than ``limit`` (OSError if it
    cannot be opened)."""
    with open(path, "rb") as stream:
        size = os.fstat(stream.fileno()).st_size
        if size > limit:
            raise TooLargeError(
                f"{os.fspath(path)} is {size / 1000**2:,.1f} MB; {what} is at most {limit / 1000**2:g} MB "
                f"(a 90-piece mannequin is 0.13 MB, a posed clip 2.8 kB a frame): refused before reading it"
            )
        return stream.read()


# ------------------------------------------------------------------------------------------------ temporaries


def temp_prefix():
    """``.ellimann-PID@HOST-``: the prefix of this process's temporary files and folders."""
    return f"{TEMP_PREFIX}{os.getpid()}@{_host()}-"


def _host():
    return re.sub(r"[^A-Za-z0-9.-]", "_", socket.gethostname() or "localhost")[:40]


_TEMP_NAME = re.compile(r"^\.ellimann-(?:(?P<pid>\d+)@(?P<host>[A-Za-z0-9._-]+)-)?[a-z0-9_]{8}(?P<tmp>\.tmp)?$")


def clean_stale_temporaries(folder, max_age=STALE_AGE):
    """Remove what killed ElliMann runs left in ``folder``: ``.ellimann-*.tmp`` files and ``.ellimann-*/``
    folders of a process of this machine that no longer runs, or older than ``max_age`` seconds (another
    machine's, on a shared folder, or from before temporaries were named by process). Returns the names
    removed. What a running ElliMann is writing (another shard into the same folder) is left alone."""
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    host, now = _host(), time.time()
    for entry in entries:
        match = _TEMP_NAME.match(entry.name)
        if not match:
            continue
        try:
            is_dir = entry.is_dir(follow_symlinks=False)
            if is_dir == bool(match["tmp"]) or (not is_dir and not entry.is_file(follow_symlinks=False)):
                continue  # ours are .tmp files and folders without a suffix
            running = _running(int(match["pid"])) if match["pid"] and match["host"] == host else None
            if running or (running is None and now - _newest(entry) < max_age):
                continue
            if is_dir:
                shutil.rmtree(entry.path)
            else:
                os.unlink(entry.path)
            removed.append(entry.name)
        except OSError:
            continue  # gone already, or not ours to remove
    return removed


def _newest(entry):
    """The latest modification time of an entry and, for a folder, of what is in it."""
    times = [entry.stat(follow_symlinks=False).st_mtime]
    if entry.is_dir(follow_symlinks=False):
        times += [inner.stat(follow_symlinks=False).st_mtime for inner in os.scandir(entry.path)]
    return max(times)


def _running(pid):
    """Whether process ``pid`` of this machine runs (None when that cannot be told)."""
    if pid == os.getpid():
        return True
    if os.name != "posix":  # os.kill(pid, 0) would end the process on Windows
        return None
    try:
        os.kill(pid, 0)
    except (ProcessLookupError, OverflowError):  # no such process (or no such pid at all)
        return False
    except OSError:  # PermissionError: it runs, as another user
        return True
    return True


# ------------------------------------------------------------------------------------------------ files another
# program writes (Blender's .blend, .glb, .obj, .png), put in place atomically with the usual permissions.


@contextlib.contextmanager
def atomic_output(path):
    """Yield a temporary path for Blender to write; once it has, rename it onto ``path`` (same folder).

    The temporary file sits in a private folder beside the target, so Blender writes a fresh file
    (no backup of an existing one, normal permissions) and one rename on the same file system puts it
    in place. It is renamed only if it is whole (``incomplete``: Blender can return
    normally from a write the disk cut short) and the disk did not fill up. Nothing is left behind on
    failure. An OSError on the way (making the folder, writing, renaming), or a RuntimeError of the
    Blender operator that wrote, is raised as an OSError with ``filename`` = ``path`` as given, not
    the temporary file's, and a one-line reason.
    """
    target = os.fspath(path)
    with _naming(target):
        path = os.path.abspath(target)
        folder = os.path.dirname(path)
        os.makedirs(folder, exist_ok=True)
        scratch = tempfile.mkdtemp(prefix=temp_prefix(), dir=folder)
    temp = os.path.join(scratch, os.path.basename(path))
    try:
        with _naming(target):
            try:
                yield temp
            except RuntimeError as error:  # what a bpy.ops call raises when Blender could not write
                if disk_full(folder):
                    raise OSError(errno.ENOSPC, "No space left on device", target) from error
                # Blender 4.x reports a full disk as "No such file or directory" (it has removed its
                # partial file by then): a write of the size of a small .blend tells.
                no_room = _no_room_for(scratch, PROBE_BYTES)
                if no_room:
                    raise OSError(no_room.errno, no_room.strerror, target) from error
                raise blender_write_error(error, temp, target) from error
            problem = incomplete(temp) if os.path.isfile(temp) else "Blender wrote nothing"
            # A whole file is kept even where the folder reports no free blocks (some network and FUSE
            # file systems always do); a cut-short one on a full disk is named as such.
            if problem and disk_full(folder):
                raise OSError(
                    errno.ENOSPC, f"No space left on device (the file Blender wrote is incomplete: {problem})", target
                )
            if problem:
                raise OSError(errno.EIO, f"the file Blender wrote is incomplete: {problem}", target)
            os.replace(temp, path)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


PROBE_BYTES = 1 << 20


def _no_room_for(folder, size):
    """The OSError (no space, quota or file size limit) that writing ``size`` bytes in ``folder`` meets
    now, or None (a scratch file, removed at once)."""
    try:
        with tempfile.TemporaryFile(dir=folder) as probe:
            probe.write(bytes(size))
            probe.flush()
            os.fsync(probe.fileno())
    except OSError as error:
        if error.errno in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
            return error
    return None


def blender_write_error(error, temp, target):
    """An OSError naming ``target`` for a Blender operator's RuntimeError while it wrote ``temp``.

    The reason is the errno Blender reports ("[Errno 28] …", "…: File name too long"), else what
    opening ``temp`` says, else Blender's first line with the temporary path replaced by ``target``.
    """
    text = str(error)
    match = re.search(r"\[Errno (\d+)\] ([^:\n'\"]+)", text)
    if match:
        return OSError(int(match.group(1)), match.group(2).strip(), target)
    names = {os.strerror(number): number for number in errno.errorcode}
    for line in text.splitlines():
        tail = line.rstrip().rsplit(": ", 1)[-1]
        if tail in names:
            return OSError(names[tail], tail, target)
    try:
        with open(temp, "ab"):
            pass
    except OSError as probe:
        return OSError(probe.errno, probe.strerror or str(probe), target)
    first = next((line.strip() for line in text.splitlines() if line.strip()), "Blender could not write it")
    first = re.sub(r"^Error:\s*", "", first).replace(temp, target).replace(os.path.dirname(temp), ".")
    return OSError(errno.EIO, f"Blender could not write it ({first[:200]})", target)


@contextlib.contextmanager
def _naming(target):
    try:
        yield
    except OSError as error:
        if error.filename == target and error.filename2 is None:
            raise
        raise OSError(error.errno, error.strerror or str(error), target) from error
