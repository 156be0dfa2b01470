"""Writing files: core formats without Blender, Blender's (.blend, .glb) through ``blender.services`` only when
asked (bpy is imported only inside the functions that need it); one-line errors naming the file; the output
folder."""

import contextlib
import importlib.util
import os
import sys
import tempfile

from ..core.errors import one_line
from ..core.files import atomic_write_text, clean_stale_temporaries
from ..core.formats.core_writers import core_format, write_core_file
from ..core.formats.table import FORMATS, format_of
from .output import PROG, UsageError, say


def blender_available():
    """Whether the bpy module can be imported (without importing it)."""
    if "bpy" in sys.modules:
        return sys.modules["bpy"] is not None
    try:
        return importlib.util.find_spec("bpy") is not None
    except (ImportError, ValueError):
        return False


def no_blender(what):
    return UsageError(
        f"{what} needs Blender: the bpy module is not installed (pip install bpy, or run "
        f"blender --background --command {PROG} …)"
    )


def ensure_registered(what="this"):
    """Import bpy; under ``python -m`` register the add-on once so ElliMann's properties exist."""
    from ..blender.services.chatter import blender_output

    with blender_output():
        try:
            import bpy
        except ImportError:
            raise no_blender(what) from None

        if not hasattr(bpy.types.Collection, "ellimann"):
            from .. import register

            register()
    return bpy


def output_kind(path):
    kind = format_of(path)
    if kind is None:
        raise UsageError(f"OUT must end in .blend, .glb, .obj, .json or .xml (MJCF), got {path!r}")
    return kind.name


def extension(kind):
    return FORMATS[kind].extension


def write(mannequin, paths, measured, cushions, frames=None, fps=None, skin=None):
    """Write every path (format from the extension); Blender is loaded only for .blend and .glb. ``frames``: the
    pose (a list of core.pose.kinematics.Pose) to write the mannequin in, if any; ``skin``: its skin
    (``core.skin.surface.Skin``, ``--skin``), written with it (``core.formats.core_writers``; .blend and .glb:
    ``blender.services``).

    A path that cannot be written raises UsageError naming it (not the temporary file behind it).
    """
    if frames is not None:
        return write_posed(mannequin, paths, cushions, frames, fps, measured, skin)
    for path in paths:
        if core_format(path):
            with writing(path):
                write_core_file(mannequin, path, cushions, skin)
    blender = [p for p in paths if core_format(p) is None]
    if blender:
        ensure_registered(f"writing {blender[0]}")
        from ..blender.services.files import write_mannequin

        try:
            write_mannequin(mannequin, blender, measured, cushions, skin=skin)
        except OSError as error:  # atomic_output names the file that failed
            if error.filename is None:
                raise
            raise cannot_write(error.filename, error) from None
    return paths


def write_posed(mannequin, paths, cushions, frames, fps, measured=None, skin=None):
    """:func:`write` of a posed mannequin (and its ``skin``): .json, .xml and .obj by the core
    (core.formats.posed_files), .blend and .glb by the Blender rig (``blender.services.posing.write_posed``)."""
    from ..core.formats.posed_files import write_posed as write_core_posed

    blender = [p for p in paths if format_of(p).needs_blender_for(True)]
    for path in [p for p in paths if p not in blender]:
        with writing(path):
            write_core_posed(mannequin, frames, path, cushions, fps, skin)
    if blender:
        ensure_registered(f"writing {blender[0]}")
        try:
            from ..blender.services.posing import write_posed as write_blender_posed
        except ImportError:
            raise UsageError(
                f"writing a posed {blender[0]} needs ElliMann's Blender rig, which this build lacks; "
                "write .json, .xml or .obj"
            ) from None
        write_blender_posed(mannequin, frames, blender, cushions, fps, measured, skin=skin)
    return paths


@contextlib.contextmanager
def writing(target, folder=False):
    """Turn an OSError while writing ``target`` (a file, or a folder with ``folder``) into one line naming it."""
    try:
        yield
    except OSError as error:
        raise cannot_write(target, error, folder) from None


def cannot_write(target, error, folder=False):
    where = os.path.abspath(target if folder else os.path.dirname(os.path.abspath(target)))
    blocker = _file_in_the_way(where)
    what = f"the folder {target}" if folder else target
    if not folder and os.path.isdir(target):
        reason = "it is a folder"
    elif blocker is not None:
        reason = "it is a file" if blocker == where and folder else f"{blocker} is a file, not a folder"
    else:
        reason = error.strerror or one_line(error)
        if error.filename and os.path.abspath(error.filename) not in (os.path.abspath(target), where):
            reason += f" (creating a file in {where})"  # the temporary file it is written through
    return UsageError(f"cannot write {what}: {reason}")


def _file_in_the_way(folder):
    """The nearest existing path at or above ``folder`` if it is not a folder (nothing can be made under it)."""
    path = folder
    while not os.path.lexists(path):
        parent = os.path.dirname(path)
        if parent == path:
            return None
        path = parent
    return None if os.path.isdir(path) else path


def output_folder(folder, command):
    """Make the output folder and check that files can be created in it, before any work is done; remove
    the temporaries a killed run of ElliMann left there (not those of one still running)."""
    with writing(folder, folder=True):
        os.makedirs(folder, exist_ok=True)
        with tempfile.TemporaryFile(prefix=".ellimann-", dir=folder):
            pass
    removed = clean_stale_temporaries(folder)
    if removed:
        say(f"{PROG} {command}: removed {len(removed)} temporary file(s) an interrupted run left in {folder}")


def write_text(path, text):
    with writing(path):
        atomic_write_text(path, text)
