"""The mannequin file formats, in one table: each format's name (``--format``), its file extension, who writes
it (the core: OBJ, JSON and MJCF, ``core.formats.core_writers``; Blender: .blend and .glb,
``blender.services.files.write_mannequin``) and so whether it needs the bpy module, the function that writes it
and what its whole-file check verifies (every file is written to a temporary name and put in place only once
``core.files.incomplete`` finds it whole, so a write cut short never replaces a file). The command line, the
writers and the export operator read it; the formats ElliMann defines have a page each in docs/formats/."""

import os
from dataclasses import dataclass


@dataclass(frozen=True)
class Format:
    name: str  # what a user types (``--format json,mjcf``)
    extension: str  # the file extension, without the dot
    writer: str  # "core" (numpy only) or "blender" (needs bpy)
    title: str  # what it is, for help texts
    posed_writer: str  # who writes it posed (``--pose``): "core" (core.formats.posed_files) or "blender"
    animated: bool  # holds an animation (the walk cycle)
    written_by: str  # the function that writes it at rest (dotted, under ellimann_addon; posed: posed_files/posing)
    whole_file: str  # what core.files.incomplete checks of it before it replaces anything

    @property
    def needs_blender(self):
        return self.writer == "blender"

    def needs_blender_for(self, posed):
        """Whether writing it (posed, with ``posed``) needs the bpy module."""
        return (self.posed_writer if posed else self.writer) == "blender"


WHOLE_FILE_CHECK = "core.files.incomplete"  # the one whole-file check, by extension (``kind``)
FORMATS = {
    f.name: f
    for f in (
        Format(
            "blend",
            "blend",
            "blender",
            "Blender file",
            "blender",
            True,
            "blender.services.files.write_blender_file",
            "its block chain reaches the ENDB block (zstd: the frames its seek table lists; gzip: every block)",
        ),
        Format(
            "glb",
            "glb",
            "blender",
            "binary glTF with ElliMann's extras",
            "blender",
            True,
            "blender.services.files.export_gltf",
            "the length in its header is the file's and its chunks fill it",
        ),
        Format(
            "obj",
            "obj",
            "core",
            "Wavefront OBJ (Y up)",
            "core",
            False,
            "core.formats.obj.write_obj",
            "it ends with a complete line",
        ),
        Format(
            "json",
            "json",
            "core",
            "ElliMann's mannequin JSON",
            "core",
            True,
            "core.mannequin.model.Mannequin.save",
            "it parses as JSON (reading it, Mannequin.load checks every field)",
        ),
        Format(
            "mjcf",
            "xml",
            "core",
            "MJCF, for MuJoCo",
            "core",
            True,
            "core.formats.mjcf.write_mjcf",
            "it parses as XML",
        ),
    )
}
# The batch's own one-file format (``batch --format npz``): every mannequin of a batch, not one per file, so not a
# row of FORMATS (which synth, pose and the export operator write one mannequin to).
BATCH_FILE = Format(
    "npz",
    "npz",
    "core",
    "every mannequin of a batch in one compressed NumPy archive",
    "core",
    False,
    "core.formats.npz_bundle.BatchFileWriter",
    "its zip directory reads (reading it, read_batch_file checks every array's shape)",
)
CORE_FORMATS = tuple(name for name, f in FORMATS.items() if not f.needs_blender)  # obj, json, mjcf
BLENDER_FORMATS = tuple(name for name, f in FORMATS.items() if f.needs_blender)  # blend, glb
EXTENSIONS = {name: f.extension for name, f in FORMATS.items()}  # format -> file extension


def extension_of(path):
    """A path's extension, lower case, without the dot ("" if none)."""
    return os.path.splitext(os.fspath(path))[1].lower().lstrip(".")


def format_of(path):
    """The Format a path's extension names, or None."""
    extension = extension_of(path)
    return next((f for f in FORMATS.values() if f.extension == extension), None)


def needs_blender(paths, posed=False):
    """Whether writing ``paths`` (posed, with ``posed``) needs the bpy module."""
    return any(f is not None and f.needs_blender_for(posed) for f in map(format_of, paths))
