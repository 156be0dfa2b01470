"""ElliMann in the 3D viewport's menus: Object > ElliMann (every mannequin operator), Add > ElliMann Ellipsoid
and Mesh > Fit Ellipsoid. (File > Export > ElliMann Mannequin is the Export feature's: ``export/menu.py``.)"""

import bpy

from .. import ids


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
        layout.operator(ids.BUILD_SKIN)
        layout.operator(ids.MEASURE_MANNEQUIN)
        layout.operator(ids.MEASURE_BODY)
        layout.operator(ids.BUILD_REFERENCE_SET)
        layout.operator(ids.SYNTHESIZE_MANNEQUIN)
        layout.operator(ids.SYNTHESIZE_FROM_MESH)
        layout.operator(ids.OPEN_MEASUREMENT_FILE)
        layout.operator(ids.DRAPE_GARMENT)
        layout.separator()
        layout.operator(ids.ADD_ARMATURE, icon="ARMATURE_DATA")
        layout.operator_menu_enum(ids.APPLY_POSE, "pose")
        layout.operator(ids.REST_POSE)
        layout.operator(ids.IMPORT_BVH, icon="IMPORT")
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


# (menu, draw function): appended on register, removed on unregister.
MENU_ENTRIES = (
    ("VIEW3D_MT_object", draw_object_menu),
    ("VIEW3D_MT_add", draw_add_menu),
    ("VIEW3D_MT_edit_mesh", draw_edit_mesh_menu),
)

classes = (ELLIMANN_MT_object,)
