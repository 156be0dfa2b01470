"""The mannequin file formats, in one table: each format's name (``--format``), its file extension, what it is, whether
it holds an animation, whether writing it needs the bpy module (at rest and posed), what its whole-file check
verifies (every file is written to a temporary name and put in place only once ``core.files.incomplete`` finds it
whole, so a write cut short never replaces a file) and the function that writes it.

A path's format is decided here once (:func:`format_of`, :func:`check_outputs`), and every list of formats in a help
or an error text is made from the table (:func:`listing`). The core writes .obj, .json and MJCF
(``core.formats.core_writers``); Blender writes .blend, .glb and the FBX avatar, and the Blender layer binds its
writers to those rows when it is loaded (:func:`bind_writer`): the core never imports it. A row that ``needs_skin``
(the FBX avatar: the skin on its bones, for garment tools) is refused by a job that asks for no skin. The formats
ElliMann defines have a page each in docs/formats/.

Every row's ``write(mannequin, paths, *, cushions, skin, measured, frames, fps)`` writes one mannequin (its
``skin``, if any; in ``frames``, a list of ``core.pose.kinematics.Pose``, if posed) to each of ``paths``, all of
that row's format, and returns them; it takes any other setting by keyword and ignores those it has no use for (the
avatar's ``avatar``: ``core.formats.avatar.AvatarOptions``).
"""

import os
from dataclasses import dataclass

from ..errors import ElliMannError
from ..files import extension_of


@dataclass(eq=False)
class Format:
    name: str  # what a user types (``--format json,mjcf``)
    extension: str  # the file extension, without the dot
    title: str  # what it is, for help texts
    animated: bool  # holds an animation (the walk cycle, a clip)
    blender: bool  # writing it at rest needs the bpy module
    blender_posed: bool  # writing it posed needs the bpy module
    whole_file: str  # what core.files.incomplete checks of it before it replaces anything
    write: object = None  # its writer (see the module's docstring); Blender's rows: bound by the Blender layer
    needs_skin: bool = False  # it holds the mannequin's skin alone (an avatar): a job without a skin is refused

    @property
    def aliases(self):
        """The other name ``--format`` takes for it: its extension where that is not its name (xml for mjcf)."""
        return (self.extension,) if self.extension != self.name else ()

    @property
    def needs_blender(self):
        return self.blender

    def needs_blender_for(self, posed):
        """Whether writing it (posed, with ``posed``) needs the bpy module."""
        return self.blender_posed if posed else self.blender

    def writer(self):
        """Its writer; ElliMannError if it is Blender's and the Blender layer is not loaded."""
        if self.write is None:
            raise ElliMannError(f"writing a .{self.extension} file needs Blender (the bpy module)")
        return self.write


def _json_files(mannequin, paths, **settings):
    from .core_writers import write_json_files  # the writers' modules are loaded when a file is written

    return write_json_files(mannequin, paths, **settings)


def _obj_files(mannequin, paths, **settings):
    from .core_writers import write_obj_files

    return write_obj_files(mannequin, paths, **settings)


def _mjcf_files(mannequin, paths, **settings):
    from .core_writers import write_mjcf_files

    return write_mjcf_files(mannequin, paths, **settings)


WHOLE_FILE_CHECK = "core.files.incomplete"  # the one whole-file check, by extension
FORMATS = {
    f.name: f
    for f in (
        Format(
            "blend",
            "blend",
            "Blender file",
            True,
            True,
            True,
            "its block chain reaches the ENDB block (zstd: the frames its seek table lists; gzip: every block)",
        ),
        Format(
            "glb",
            "glb",
            "binary glTF with ElliMann's extras",
            True,
            True,
            True,
            "the length in its header is the file's and its chunks fill it",
        ),
        Format("obj", "obj", "Wavefront OBJ (Y up)", False, False, False, "it ends with a complete line", _obj_files),
        Format(
            "json",
            "json",
            "ElliMann's mannequin JSON",
            True,
            False,
            False,
            "it parses as JSON (reading it, Mannequin.load checks every field)",
            _json_files,
        ),
        Format("mjcf", "xml", "MJCF, for MuJoCo", True, False, False, "it parses as XML", _mjcf_files),
        Format(
            "fbx",
            "fbx",
            "FBX avatar for garment tools (the skin on 24 bones, Y up)",
            False,
            True,
            True,
            "it starts with the binary FBX signature and ends with its footer",
            needs_skin=True,
        ),
    )
}
# The batch's own one-file format (``batch --format npz``): every mannequin of a batch, not one per file, so not a
# row of FORMATS (which synth, pose and the export operator write one mannequin to).
BATCH_FILE = Format(
    "npz",
    "npz",
    "every mannequin of a batch in one compressed NumPy archive",
    False,
    False,
    False,
    "its zip directory reads (reading it, read_batch_file checks every array's shape)",
)
CORE_FORMATS = tuple(name for name, f in FORMATS.items() if not f.blender)  # obj, json, mjcf
BLENDER_FORMATS = tuple(name for name, f in FORMATS.items() if f.blender)  # blend, glb, fbx
AVATAR_FORMATS = tuple(name for name, f in FORMATS.items() if f.needs_skin)  # fbx
SCENE_FORMATS = tuple(name for name in BLENDER_FORMATS if name not in AVATAR_FORMATS)  # blend, glb: one scene


def format_of(path):
    """The Format a path's extension names, or None: where every path's format is decided."""
    extension = extension_of(path)
    return next((f for f in FORMATS.values() if f.extension == extension), None)


def format_named(name, batch=False):
    """The Format ``--format`` names by ``name`` or an alias (``batch``: the batch file too), or None."""
    name = name.strip().lower().lstrip(".")
    rows = [*FORMATS.values(), *([BATCH_FILE] if batch else [])]
    return next((f for f in rows if name == f.name or name in f.aliases), None)


def listing(rows=None, what="extension"):
    """The formats as a help or an error text says them: ".blend, .glb, .obj, .json or .xml (MJCF)" (``what``
    "extension") or "blend, glb, obj, json, mjcf (xml)" ("name")."""
    rows = list(FORMATS.values() if rows is None else rows)
    if what == "name":
        return ", ".join(f.name + (f" ({', '.join(f.aliases)})" if f.aliases else "") for f in rows)
    words = [f".{f.extension}" + (f" ({f.name.upper()})" if f.aliases else "") for f in rows]
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " or " + words[-1]


def check_outputs(paths, motion=None):
    """{path: Format} of output ``paths``, decided once; ElliMannError naming the path for one whose extension names
    no format, and, with ``motion`` (the name of a pose that moves: a walk, a clip), for a format that holds no
    animation."""
    formats = {}
    for path in paths:
        kind = format_of(path)
        if kind is None:
            raise ElliMannError(f"{os.fspath(path)!r}: an output file must end in {listing()}")
        if motion is not None and not kind.animated:
            moving = listing([f for f in FORMATS.values() if f.animated])
            raise ElliMannError(
                f"{os.fspath(path)!r}: --pose {motion} is an animation and a .{kind.extension} file holds none; "
                f"write {moving}"
            )
        formats[os.fspath(path)] = kind
    return formats


def bind_writer(names, write):
    """The Blender layer's writer for the rows ``names`` (it needs bpy, which the core never imports)."""
    for name in names:
        FORMATS[name].write = write


def write_files(mannequin, formats, **settings):
    """Write ``mannequin`` to every path of ``formats`` ({path: Format}, :func:`check_outputs`), the paths of one
    writer together (Blender's .blend and .glb from one scene); ``settings``: cushions, skin, measured, frames, fps.
    Returns the paths."""
    groups = {}
    for path, kind in formats.items():
        groups.setdefault(id(kind.writer()), (kind.writer(), []))[1].append(path)
    for write, paths in groups.values():
        write(mannequin, paths, **settings)
    return list(formats)


def write_file(mannequin, path, **settings):
    """Write ``mannequin`` to one ``path`` (its format from its extension): :func:`write_files` for a script or a
    test."""
    return write_files(mannequin, check_outputs([path]), **settings)[0]
