"""Naming, undo and tooltips of every registered operator, panel and menu."""

import bpy
import pytest

from ellimann_addon.blender import ids, menus, operators, panels

OPERATORS = operators.classes()
ALL_IDS = [v for k, v in vars(ids).items() if k.isupper() and isinstance(v, str) and v.startswith("ellimann.")]
READ_ONLY = {ids.VALIDATE_MANNEQUIN, ids.ADD_MEASUREMENT_PRESET}


def registered_operator_names():
    return [name for name in dir(bpy.ops.ellimann) if not name.startswith("_")]


def test_every_registered_operator_is_named_by_the_convention():
    names = registered_operator_names()
    assert sorted(f"ellimann.{n}" for n in names) == sorted(ALL_IDS)
    for cls in OPERATORS:
        assert cls.bl_idname.startswith("ellimann.") and cls.__name__ == ids.class_name(cls.bl_idname)
        assert hasattr(bpy.types, cls.__name__)
    for cls in panels.classes + (menus.ELLIMANN_MT_object,):
        assert cls.__name__.startswith(("ELLIMANN_PT_", "ELLIMANN_MT_")) and cls.bl_idname == cls.__name__


@pytest.mark.parametrize("cls", OPERATORS, ids=lambda c: c.bl_idname)
def test_operators_have_poll_tooltip_and_undo_when_they_change_data(cls):
    assert "poll" in vars(cls)
    assert cls.__doc__ and len(cls.__doc__.split()) >= 5
    assert "REGISTER" in cls.bl_options
    assert ("UNDO" in cls.bl_options) == (cls.bl_idname not in READ_ONLY)
    rna = getattr(bpy.ops.ellimann, cls.bl_idname.partition(".")[2]).get_rna_type()
    assert rna.description == cls.__doc__ and "\n" not in cls.__doc__  # Blender shows it verbatim


def test_sub_panels_hang_under_the_main_panel_in_their_order():
    subs = [cls for cls in panels.classes if cls.bl_idname != ids.PANEL_MAIN]
    assert all(cls.bl_parent_id == ids.PANEL_MAIN for cls in subs)
    assert [cls.bl_order for cls in subs] == sorted(ids.PANEL_ORDER.values())
    assert max(ids.PANEL_ORDER.values()) < 60  # room for Synthesize and Drape
