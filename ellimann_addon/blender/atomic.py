"""Files Blender itself writes (.blend, .glb, .obj, .png), put in place atomically with the usual permissions.

Every output of the add-on goes through here or through ``core.files`` (JSON, MJCF), so a failed
write never leaves a half-written file and every format gets the same permissions.
"""

import contextlib
import errno
import os
import shutil
import tempfile


@contextlib.contextmanager
def atomic_output(path):
    """Yield a temporary path for Blender to write; once it has, rename it onto ``path`` (same folder).

    The temporary file sits in a private folder beside the target, so Blender writes a fresh file
    (no backup of an existing one, normal permissions) and one rename on the same file system puts it
    in place. Nothing is left behind on failure. An OSError on the way (making the folder, writing,
    renaming) is raised again with ``filename`` = ``path`` as given, not the temporary file's.
    """
    target = os.fspath(path)
    with _naming(target):
        path = os.path.abspath(target)
        folder = os.path.dirname(path)
        os.makedirs(folder, exist_ok=True)
        scratch = tempfile.mkdtemp(prefix=".ellimann-", dir=folder)
    temp = os.path.join(scratch, os.path.basename(path))
    try:
        with _naming(target):
            yield temp
            if not os.path.isfile(temp) or not os.path.getsize(temp):
                raise OSError(errno.EIO, "Blender wrote nothing", target)
            os.replace(temp, path)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


@contextlib.contextmanager
def _naming(target):
    try:
        yield
    except OSError as error:
        if error.filename == target and error.filename2 is None:
            raise
        raise OSError(error.errno, error.strerror or str(error), target) from error
