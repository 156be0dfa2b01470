"""Files Blender itself writes (.blend, .glb, .obj, .png), put in place atomically with the usual permissions.

Every output of the add-on goes through here or through ``core.files`` (JSON, MJCF), so a failed
write never leaves a half-written file and every format gets the same permissions.
"""

import contextlib
import os
import shutil
import tempfile


@contextlib.contextmanager
def atomic_output(path):
    """Yield a temporary path for Blender to write; once it has, rename it onto ``path`` (same folder).

    The temporary file sits in a private folder beside the target, so Blender writes a fresh file
    (no backup of an existing one, normal permissions) and one rename on the same file system puts it
    in place. Nothing is left behind on failure.
    """
    path = os.path.abspath(os.fspath(path))
    folder = os.path.dirname(path)
    os.makedirs(folder, exist_ok=True)
    scratch = tempfile.mkdtemp(prefix=".ellimann-", dir=folder)
    temp = os.path.join(scratch, os.path.basename(path))
    try:
        yield temp
        if not os.path.isfile(temp) or not os.path.getsize(temp):
            raise OSError(f"Blender wrote nothing to {path}")
        os.replace(temp, path)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
