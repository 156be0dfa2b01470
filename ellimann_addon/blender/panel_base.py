"""One base for every ElliMann sidebar panel (3D viewport > sidebar > ElliMann tab)."""

CATEGORY = "ElliMann"


class ElliMannPanel:
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = CATEGORY
