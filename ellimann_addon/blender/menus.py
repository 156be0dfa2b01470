"""ElliMann in Blender's menus: Add > ElliMann Ellipsoid, Object > ElliMann, Mesh > Fit Ellipsoid (3D viewport) and
File > Export > ElliMann Mannequin."""

import bpy

from . import ids


class ELLIMANN_MT_object(bpy.types.Menu):
    """ElliMann tools for mannequin collections and their ellipsoids"""

    bl_idname = ids.MENU_OBJECT
    bl_label = "ElliMann"

    def draw(self, context):
        layout = self.layout
        layout.operator(ids.NEW_MANNEQUIN)
        layout.operator(ids.ADD_ELLIPSOID)
        layout.separator()
        layout.operator(ids.MIRROR_ELLIPSOIDS)
        layout.operator(ids.MIRROR_SIDE)
        layout.separator()
        layout.operator(ids.RELABEL_AXES)
        layout.operator(ids.SYMMETRIZE_CENTRAL)
        layout.operator(ids.REGISTER_MANNEQUIN)
        layout.separator()
        layout.operator(ids.BUILD_CUSHIONS)
        layout.operator(ids.MEASURE_MANNEQUIN)
        layout.operator(ids.SYNTHESIZE_MANNEQUIN)
        layout.operator(ids.DRAPE_GARMENT)
        layout.separator()
        layout.operator(ids.VALIDATE_MANNEQUIN)
        layout.operator(ids.FIX_FRAMES)
        layout.separator()
        layout.operator(ids.EXPORT_MANNEQUIN, icon="EXPORT")


def draw_object_menu(self, context):
    self.layout.separator()
    self.layout.menu(ids.MENU_OBJECT)


def draw_add_menu(self, context):
    self.layout.operator(ids.ADD_ELLIPSOID, text="ElliMann Ellipsoid", icon="MESH_UVSPHERE")


def draw_edit_mesh_menu(self, context):
    self.layout.separator()
    self.layout.operator(ids.FIT_ELLIPSOID, text="Fit ElliMann Ellipsoid")


def draw_export_menu(self, context):
    self.layout.operator(ids.EXPORT_MANNEQUIN, text="ElliMann Mannequin (.glb, .xml)")


# (menu, draw function): appended on register, removed on unregister.
MENU_ENTRIES = (
    ("VIEW3D_MT_object", draw_object_menu),
    ("VIEW3D_MT_add", draw_add_menu),
    ("VIEW3D_MT_edit_mesh", draw_edit_mesh_menu),
    ("TOPBAR_MT_file_export", draw_export_menu),
)


def register():
    bpy.utils.register_class(ELLIMANN_MT_object)
    for menu, draw in MENU_ENTRIES:
        getattr(bpy.types, menu).append(draw)


def unregister():
    for menu, draw in reversed(MENU_ENTRIES):
        getattr(bpy.types, menu).remove(draw)
    bpy.utils.unregister_class(ELLIMANN_MT_object)
