"""File > Export > ElliMann Mannequin."""

from ... import ids


def draw_export_menu(self, context):
    self.layout.operator(ids.EXPORT_MANNEQUIN, text="ElliMann Mannequin (.glb, .xml)")


# (menu, draw function): appended on register, removed on unregister.
MENU_ENTRIES = (("TOPBAR_MT_file_export", draw_export_menu),)
