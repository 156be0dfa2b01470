"""The mannequin file formats, in one table: each format's name (``--format``), its file extension, who writes
it (the core: OBJ, JSON and MJCF, ``core.formats.core_writers``; Blender: .blend and .glb,
``blender.services.files.write_mannequin``)
and so whether it needs the bpy module. The command line, the writers and the export operator read it."""

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

    @property
    def needs_blender(self):
        return self.writer == "blender"

    def needs_blender_for(self, posed):
        """Whether writing it (posed, with ``posed``) needs the bpy module."""
        return (self.posed_writer if posed else self.writer) == "blender"


FORMATS = {
    f.name: f
    for f in (
        Format("blend", "blend", "blender", "Blender file", "blender", True),
        Format("glb", "glb", "blender", "binary glTF with ElliMann's extras", "blender", True),
        Format("obj", "obj", "core", "Wavefront OBJ (Y up)", "core", False),
        Format("json", "json", "core", "ElliMann's mannequin JSON", "core", True),
        Format("mjcf", "xml", "core", "MJCF, for MuJoCo", "core", True),
    )
}
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
