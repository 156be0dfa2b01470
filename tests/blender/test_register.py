"""Enable -> disable -> enable in this process leaves nothing behind and works again."""

import bpy

import ellimann_addon
from ellimann_addon.blender import registry
from ellimann_addon.blender.features.skin import live as skin_live
from ellimann_addon.blender.features.synthesize import live


def all_classes():
    return list(registry.CLASSES)


def leftovers():
    """Everything of ElliMann still registered with Blender."""
    found = [name for name in dir(bpy.types) if name.startswith("ELLIMANN")]
    found += [cls.__name__ for cls in all_classes() if cls.is_registered]
    found += [
        f"{owner.__name__}.ellimann"
        for owner in (bpy.types.Object, bpy.types.Collection, bpy.types.Scene)
        if hasattr(owner, "ellimann")
    ]
    found += [f"Scene.{name}" for name in ("ellimann_synthesis", "ellimann_drape") if hasattr(bpy.types.Scene, name)]
    found += [f"bpy.ops.ellimann.{name}" for name in dir(bpy.ops.ellimann) if not name.startswith("_")]
    found += [
        f"{menu} entry" for menu, draw in registry.MENU_ENTRIES if draw in getattr(bpy.types, menu)._dyn_ui_initialize()
    ]
    found += [
        f"bpy.app.handlers.{name}: {handler.__name__}"
        for name in dir(bpy.app.handlers)
        if isinstance(getattr(bpy.app.handlers, name), list)
        for handler in getattr(bpy.app.handlers, name)
        if getattr(handler, "__module__", "").startswith(ellimann_addon.__name__)
    ]
    found += ["bpy.app.timers: settle"] if bpy.app.timers.is_registered(live._settle_timer) else []
    found += ["bpy.app.timers: skin settle"] if bpy.app.timers.is_registered(skin_live._settle_timer) else []
    found += [f"live follower: {f.__name__}" for f in live._followers]
    return found


def test_disable_leaves_nothing_and_enable_works_again():
    # property groups, operators, panels, menus (the Synthesize, Reference Set and Pose features' among them)
    # + Measure Body Mesh, Synthesize from Mesh; Build Skin and its panel; Open Measurement File
    assert len(all_classes()) == 2 + 14 + 6 + 1 + 2 + 6 + 6 + 6 + 2 + 2 + 1
    assert len(all_classes()) == len(set(all_classes()))
    assert not [c.__name__ for c in all_classes() if not c.is_registered]
    live._settle_later(bpy.context.scene)  # a live update's timers, still waiting
    skin_live._settle_later(bpy.context.scene)
    assert {
        "Object.ellimann",
        "Scene.ellimann_drape",
        "bpy.ops.ellimann.drape_garment",
        "VIEW3D_MT_add entry",
        "TOPBAR_MT_file_export entry",
        "bpy.app.timers: settle",
        "bpy.app.timers: skin settle",
        "live follower: follow",
        "bpy.app.handlers.undo_post: settle_restored",
        "bpy.app.handlers.redo_post: settle_restored",
        "bpy.app.handlers.load_post: settle_restored",
    } <= set(leftovers())
    ellimann_addon.unregister()
    try:
        assert leftovers() == []
    finally:
        ellimann_addon.register()
    assert not [c.__name__ for c in all_classes() if not c.is_registered]
    assert [h for h in bpy.app.handlers.undo_post if h is live.settle_restored] == [live.settle_restored]
    bpy.ops.ellimann.new_mannequin(name="Again")
    assert bpy.ops.ellimann.add_ellipsoid() == {"FINISHED"}
    assert bpy.data.collections["Again"].ellimann.is_mannequin
