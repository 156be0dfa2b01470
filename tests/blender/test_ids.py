"""Naming, undo and tooltips of every registered operator, panel and menu."""

import bpy
import pytest

from ellimann_addon.blender import ids, registry
from ellimann_addon.blender.features import menus
from ellimann_addon.blender.features.drape import panel as drape_panel
from ellimann_addon.blender.features.synthesize import panel as synthesize_panel
from ellimann_addon.blender.features.synthesize import presets as synthesize_presets
from ellimann_addon.blender.features.synthesize.operators import ELLIMANN_OT_synthesize_mannequin

OPERATORS = registry.operators()
# Everything whose properties show tooltips: the property groups and every operator.
# test_tooltips_cover_everything_registered keeps this list complete.
PROPERTY_GROUPS = registry.property_groups()
TOOLTIP_OWNERS = PROPERTY_GROUPS + OPERATORS
PANELS = registry.panels()
ALL_IDS = [v for k, v in vars(ids).items() if k.isupper() and isinstance(v, str) and v.startswith("ellimann.")]
READ_ONLY = {ids.VALIDATE_MANNEQUIN, ids.ADD_MEASUREMENT_PRESET, ids.EXPORT_MANNEQUIN}


def registered_operator_names():
    return [name for name in dir(bpy.ops.ellimann) if not name.startswith("_")]


def test_every_registered_operator_is_named_by_the_convention():
    names = registered_operator_names()
    assert sorted(f"ellimann.{n}" for n in names) == sorted(ALL_IDS)
    for cls in OPERATORS:
        assert cls.bl_idname.startswith("ellimann.") and cls.__name__ == ids.class_name(cls.bl_idname)
        assert hasattr(bpy.types, cls.__name__)
    for cls in PANELS + [menus.ELLIMANN_MT_object]:
        assert cls.__name__.startswith(("ELLIMANN_PT_", "ELLIMANN_MT_")) and cls.bl_idname == cls.__name__


@pytest.mark.parametrize("cls", OPERATORS, ids=lambda c: c.bl_idname)
def test_operators_have_poll_tooltip_and_undo_when_they_change_data(cls):
    assert any("poll" in vars(k) for k in cls.__mro__ if not k.__module__.startswith("bpy"))  # its own, or its base's
    assert cls.__doc__ and len(cls.__doc__.split()) >= 5
    assert "REGISTER" in cls.bl_options
    assert ("UNDO" in cls.bl_options) == (cls.bl_idname not in READ_ONLY)
    rna = getattr(bpy.ops.ellimann, cls.bl_idname.partition(".")[2]).get_rna_type()
    assert rna.description == cls.__doc__ and "\n" not in cls.__doc__  # Blender shows it verbatim


def test_sub_panels_hang_under_the_main_panel_in_their_order():
    subs = [cls for cls in PANELS if cls.bl_idname != ids.PANEL_MAIN]
    assert all(cls.bl_parent_id == ids.PANEL_MAIN for cls in subs)
    assert [cls.bl_order for cls in subs] == sorted(ids.PANEL_ORDER.values()) + [
        ids.SYNTHESIZE_ORDER,
        ids.POSE_ORDER,
        ids.DRAPE_ORDER,
    ]
    assert max(ids.PANEL_ORDER.values()) < ids.SYNTHESIZE_ORDER < ids.POSE_ORDER < ids.DRAPE_ORDER  # they come last


def test_the_other_modules_use_the_ids_of_ids_py():
    """ids.py holds every id, including those of the Synthesize and Drape modules (whatever they spell them with)."""
    assert ELLIMANN_OT_synthesize_mannequin.bl_idname == ids.SYNTHESIZE_MANNEQUIN
    assert synthesize_presets.ELLIMANN_OT_add_measurement_preset.bl_idname == ids.ADD_MEASUREMENT_PRESET
    assert synthesize_presets.ELLIMANN_MT_measurement_presets.bl_idname == ids.MENU_MEASUREMENT_PRESETS
    assert synthesize_presets.ELLIMANN_OT_add_measurement_preset.preset_menu == ids.MENU_MEASUREMENT_PRESETS
    for panel, order in (
        (synthesize_panel.ELLIMANN_PT_synthesize, ids.SYNTHESIZE_ORDER),
        (drape_panel.ELLIMANN_PT_drape, ids.DRAPE_ORDER),
    ):
        assert panel.__name__ == panel.bl_idname and panel.bl_idname in (ids.PANEL_SYNTHESIZE, ids.PANEL_DRAPE)
        assert (panel.bl_parent_id, panel.bl_order) == (ids.PANEL_MAIN, order)


def rna_of(cls):
    if issubclass(cls, bpy.types.Operator):
        return getattr(bpy.ops.ellimann, cls.bl_idname.partition(".")[2]).get_rna_type()
    return cls.bl_rna


def missing_tooltips(rna):
    """Properties (and enum items) of ``rna`` without a description. Hidden properties never show one."""
    missing = []
    for prop in rna.properties:
        if prop.identifier == "rna_type" or prop.is_hidden:
            continue
        if not prop.description.strip():
            missing.append(prop.identifier)
        if prop.type == "ENUM":
            missing += [
                f"{prop.identifier}['{item.identifier}']" for item in prop.enum_items if not item.description.strip()
            ]
    return missing


@pytest.mark.parametrize("cls", TOOLTIP_OWNERS, ids=lambda c: c.__name__)
def test_every_property_and_enum_item_has_a_tooltip(cls):
    assert missing_tooltips(rna_of(cls)) == []


def test_tooltips_cover_everything_registered():
    groups = {
        c.__name__
        for c in bpy.types.PropertyGroup.__subclasses__()
        if c.__name__.startswith("ELLIMANN_") and c.is_registered
    }
    assert {"ELLIMANN_PG_part", "ELLIMANN_PG_mannequin", "ELLIMANN_PG_synthesis", "ELLIMANN_PG_drape"} <= groups
    operator_classes = {ids.class_name(f"ellimann.{name}") for name in registered_operator_names()}
    assert {c.__name__ for c in TOOLTIP_OWNERS} == groups | operator_classes


def test_missing_tooltips_finds_properties_and_items_without_one():
    class ELLIMANN_PG_tooltip_probe(bpy.types.PropertyGroup):
        bare: bpy.props.IntProperty(name="Bare")
        told: bpy.props.EnumProperty(
            name="Told", description="Has one", items=(("A", "A", "Item with a tooltip"), ("B", "B", ""))
        )
        hidden: bpy.props.BoolProperty(options={"HIDDEN"})

    bpy.utils.register_class(ELLIMANN_PG_tooltip_probe)
    try:
        assert missing_tooltips(ELLIMANN_PG_tooltip_probe.bl_rna) == ["bare", "told['B']"]
    finally:
        bpy.utils.unregister_class(ELLIMANN_PG_tooltip_probe)
