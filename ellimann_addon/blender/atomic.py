"""Files Blender itself writes (.blend, .glb, .obj, .png), put in place atomically with the usual permissions.

Every output of the add-on goes through here or through ``core.files`` (JSON, MJCF), so a failed
write never leaves a half-written file and every format gets the same permissions.
"""

import contextlib
import errno
import os
import re
import shutil
import tempfile

from ..core.files import disk_full, incomplete, temp_prefix


@contextlib.contextmanager
def atomic_output(path):
    """Yield a temporary path for Blender to write; once it has, rename it onto ``path`` (same folder).

    The temporary file sits in a private folder beside the target, so Blender writes a fresh file
    (no backup of an existing one, normal permissions) and one rename on the same file system puts it
    in place. It is renamed only if it is whole (``core.files.incomplete``: Blender can return
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
            full = disk_full(folder)
            if full:
                reason = f"the file Blender wrote is incomplete: {problem}" if problem else "the disk filled up"
                raise OSError(errno.ENOSPC, f"No space left on device ({reason})", target)
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
