"""Writing a job's files by the format table's writers (``core.formats.table``): the core's without Blender,
Blender's (.blend, .glb) through ``blender.services.writers`` only when asked (bpy is imported only inside the
functions that need it); one-line errors naming the file; the output folder."""

import contextlib
import dataclasses
import importlib.util
import os
import sys
import tempfile

from ..core.errors import one_line
from ..core.files import atomic_write_text, clean_stale_temporaries
from ..core.formats.table import write_files
from .output import PROG, UsageError, blender_used, say


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


def blender_module(what="this"):
    """bpy, imported (UsageError naming ``what`` without it), with what ElliMann's Blender code needs of the add-on
    registered under ``python -m``: the ``ellimann`` properties of objects and collections (``blender.bridge.props``),
    not its panels and operators (nor, through them, the command line again)."""
    blender_used()  # what Blender prints from here on is kept out of ElliMann's lines
    from ..blender.services.chatter import blender_output

    with blender_output():
        try:
            import bpy
        except ImportError:
            raise no_blender(what) from None
        if not hasattr(bpy.types.Collection, "ellimann"):
            from ..blender.bridge import props

            for cls in props.classes:
                bpy.utils.register_class(cls)
            props.register_hooks()
    return bpy


def blender_writers(what="this"):
    """:func:`blender_module`, and the format table's Blender rows made writable (``blender.services.writers`` binds
    their writer)."""
    bpy = blender_module(what)
    from ..blender.services.chatter import blender_output

    with blender_output():
        from ..blender.services import writers  # noqa: F401  (binds the .blend and .glb rows' writer)
    return bpy


def write(result, formats, cushions=False, avatar=None):
    """Write a job's ``result`` (``core.job.result.Result``: the mannequin, its skin, its poses) to every path of
    ``formats`` ({path: Format}, decided once by the job), each by its row's writer (``core.formats.table``);
    Blender is loaded only for .blend, .glb and .fbx. ``avatar``: the job's AvatarOptions for an .fbx (what it must
    measure: ``Result.avatar_request``). A path that cannot be written raises UsageError naming it (not the
    temporary file behind it)."""
    posed = result.frames is not None
    blender = [path for path, kind in formats.items() if kind.needs_blender_for(posed)]
    if blender:
        blender_writers(f"writing {blender[0]}")
    settings = dict(
        cushions=cushions,
        skin=result.skin.skin if result.skin is not None else None,
        measured=result.five if result.measured else None,
        frames=result.frames,
        fps=result.fps,
    )
    if avatar is not None:
        settings["avatar"] = dataclasses.replace(avatar, request=result.avatar_request())
    for path, kind in formats.items():  # the core's files one at a time: an error names its file
        if not kind.needs_blender_for(posed):
            with writing(path):
                write_files(result.mannequin, {path: kind}, **settings)
    if blender:  # Blender's together, from one scene
        try:
            write_files(result.mannequin, {path: formats[path] for path in blender}, **settings)
        except OSError as error:  # atomic_output names the file that failed
            if error.filename is None:
                raise
            raise cannot_write(error.filename, error) from None
    return list(formats)


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
