"""Export: the active mannequin as binary glTF with ElliMann's extras (.glb) or MuJoCo MJCF (.xml)."""

from . import menu, operator

classes = operator.classes
MENU_ENTRIES = menu.MENU_ENTRIES
