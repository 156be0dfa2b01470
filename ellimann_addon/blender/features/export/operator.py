"""Export the active mannequin from the GUI: binary glTF with ElliMann's extras (.glb) or MuJoCo MJCF (.xml).

File > Export > ElliMann Mannequin, or the button in the sidebar's ElliMann tab. The writers are the
ones the CLI uses (:func:`...services.files.export_gltf`, :func:`...core.formats.mjcf.write_mjcf`), so a file
written here is the same as ``ellimann synth -o``'s.
"""

import os

import bpy
from bpy.props import BoolProperty, EnumProperty, StringProperty
from bpy_extras.io_utils import ExportHelper

from ....core.errors import ElliMannError
from ....core.formats import table
from ....core.formats.mjcf import write_mjcf
from ....core.formats.table import FORMATS
from ... import ids
from ...bridge.built import built_objects
from ...bridge.convert import collection_to_mannequin
from ...bridge.selection import active_mannequin
from ...services.files import export_gltf
from ..base import MannequinOperator, OperatorError, fix_first

FORMAT_ITEMS = (
    (
        "GLB",
        "glTF Binary (.glb)",
        "Binary glTF: one node per piece named after its part, with the part fields, "
        "frames and measurements as extras (three.js, game engines)",
    ),
    (
        "MJCF",
        "MJCF (.xml)",
        "MuJoCo model: a native ellipsoid geom per part (or a convex mesh per cushion pair), "
        "welded to the world, measurements in <custom>",
    ),
)
EXTENSIONS = {kind: "." + FORMATS[kind.lower()].extension for kind in ("GLB", "MJCF")}  # core.formats.table
NAMES = {"GLB": "glTF", "MJCF": "MJCF"}


def format_of(path):
    """The format a path's extension names ('GLB', 'MJCF': its row of the format table, ``table.format_of``), or
    None for any other."""
    kind = table.format_of(path)
    return kind.name.upper() if kind is not None and kind.name.upper() in EXTENSIONS else None


def with_extension(path, kind):
    """``path`` ending in the extension of format ``kind``: the other format's extension is replaced, any
    other one kept (``a.b`` -> ``a.b.glb``)."""
    stem = os.path.splitext(path)[0] if format_of(path) else path
    return stem + EXTENSIONS[kind]


def default_path(collection_name, blend_path, kind):
    """The file browser's first suggestion: the mannequin's name, beside the .blend if it is saved."""
    name = bpy.path.display_name_to_filepath(collection_name) + EXTENSIONS[kind]
    folder = os.path.dirname(blend_path)
    return os.path.join(folder, name) if folder else name


def reconcile(path, kind, last_kind):
    """(path, format) after an edit in the file browser: if the format was changed (it is not ``last_kind``),
    the extension follows it; if the file name was given the other format's extension, the format follows."""
    typed = format_of(path)
    if typed is not None and typed != kind and kind == last_kind:
        kind = typed
    return with_extension(path, kind), kind


class ELLIMANN_OT_export_mannequin(MannequinOperator, bpy.types.Operator, ExportHelper):
    """Export the active mannequin as binary glTF with ElliMann's extras (.glb) or as a MuJoCo MJCF model (.xml)"""

    bl_idname = ids.EXPORT_MANNEQUIN
    bl_label = "Export Mannequin"
    bl_options = {"REGISTER"}  # writes a file; nothing in the Blender file changes

    filename_ext = EXTENSIONS["GLB"]  # ExportHelper's default; check() follows the format
    # ExportHelper's filepath, but not remembered: Blender restores an operator's last-used properties, so
    # the next export (of another mannequin, perhaps) would suggest this one's file.
    filepath: StringProperty(
        name="File Path", description="File to export to", maxlen=1024, subtype="FILE_PATH", options={"SKIP_SAVE"}
    )
    filter_glob: StringProperty(default="*.glb;*.xml", options={"HIDDEN"})
    format: EnumProperty(
        name="Format",
        items=FORMAT_ITEMS,
        default="GLB",
        description="File format (a file name ending in .glb or .xml chooses it)",
    )
    cushions: BoolProperty(
        name="Cushions as Convex Meshes",
        default=False,
        description="MJCF: one convex mesh geom per cushion pair instead of its two ellipsoids "
        "(a .glb holds what the mannequin shows: its built cushions, if any)",
    )
    last_format: StringProperty(options={"HIDDEN", "SKIP_SAVE"})  # the format check() saw last

    OBJECT_MODE_ONLY = False

    def invoke(self, context, event):
        """Suggest the active mannequin's name as the file, and cushions if it has built ones (unless the
        caller set them: a last-used value Blender restores is only a "ghost", not set)."""
        collection = active_mannequin(context)
        if not self.properties.is_property_set("cushions", ghost=False):
            self.cushions = bool(built_objects(collection, "CUSHION"))
        if not self.filepath:
            self.filepath = default_path(collection.name, bpy.data.filepath, self.format)
        self.last_format = self.format
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def check(self, context):
        """Keep the file name's extension and the format in step (the file browser calls this on changes)."""
        if not os.path.basename(self.filepath):
            return False
        path, kind = reconcile(self.filepath, self.format, self.last_format)
        changed = (path, kind) != (self.filepath, self.format)
        if changed:
            self.filepath, self.format = path, kind
        self.last_format = kind
        return changed

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.prop(self, "format")
        row = layout.row()
        row.enabled = self.format == "MJCF"
        row.prop(self, "cushions")

    def run(self, context, collection):
        path = bpy.path.abspath(self.filepath)
        if not os.path.basename(path):
            raise OperatorError("Choose a file name to export to")
        kind = format_of(path)  # .glb or .xml decides the format; any other name gets the format's extension
        if kind is None:  # as check() does in the file browser: "ElliMann 159.5-43" -> "ElliMann 159.5-43.glb"
            kind, path = self.format, with_extension(path, self.format)
        try:
            with fix_first(collection):
                if kind == "GLB":
                    export_gltf(collection, path)
                else:
                    write_mjcf(collection_to_mannequin(collection), path, cushions=self.cushions)
        except (ElliMannError, OSError) as error:
            raise OperatorError(f"Cannot export '{collection.name}': {error}") from error
        what = "MJCF with cushion meshes" if kind == "MJCF" and self.cushions else NAMES[kind]
        self.report({"INFO"}, f"Exported '{collection.name}' ({what}) to {path}")
        return {"FINISHED"}


classes = (ELLIMANN_OT_export_mannequin,)
