"""Run by test_extension.py in a fresh Python: install the built zip the way Blender does, use it,
disable it, enable it again. Prints one JSON line with what it found; exits 1 on any failure.

Usage: python installed_extension.py ZIP USER_RESOURCES_DIR
"""

import importlib.util
import json
import os
import sys

os.environ["BLENDER_USER_RESOURCES"] = sys.argv[2]  # before bpy is imported

import bpy  # noqa: E402

MODULE = "bl_ext.user_default.ellimann"
report = {}


def leftovers():
    found = [name for name in dir(bpy.types) if name.startswith("ELLIMANN")]
    found += [
        f"{t.__name__}.ellimann"
        for t in (bpy.types.Object, bpy.types.Collection, bpy.types.Scene)
        if hasattr(t, "ellimann")
    ]
    found += [f"bpy.ops.ellimann.{n}" for n in dir(bpy.ops.ellimann) if not n.startswith("_")]
    for menu in ("VIEW3D_MT_object", "VIEW3D_MT_add", "VIEW3D_MT_edit_mesh"):
        found += [
            f"{menu}: {f.__module__}"
            for f in getattr(bpy.types, menu)._dyn_ui_initialize()
            if "ellimann" in getattr(f, "__module__", "")
        ]
    return found


def use_it(tag):
    bpy.ops.wm.read_homefile(use_empty=True)
    results = [
        bpy.ops.ellimann.new_mannequin(name=tag),
        bpy.ops.ellimann.add_ellipsoid(semi_axes=(0.1, 0.1, 0.3)),
        bpy.ops.ellimann.measure_mannequin(),
    ]
    collection = bpy.data.collections[tag]
    return [sorted(r) for r in results], round(collection.ellimann.measured[0], 3)


report["in_tree_importable"] = importlib.util.find_spec("ellimann_addon") is not None
report["install"] = sorted(
    bpy.ops.extensions.package_install_files(filepath=sys.argv[1], repo="user_default", enable_on_install=True)
)
report["enabled"] = MODULE in bpy.context.preferences.addons
report["operator_module"] = bpy.types.ELLIMANN_OT_add_ellipsoid.__module__
report["first_use"] = use_it("First")
bpy.ops.preferences.addon_disable(module=MODULE)
report["after_disable"] = leftovers()
bpy.ops.preferences.addon_enable(module=MODULE)
report["second_use"] = use_it("Second")
bpy.ops.preferences.addon_disable(module=MODULE)
report["after_second_disable"] = leftovers()
print(json.dumps(report), flush=True)
# Blender 4.x as a module segfaults in its own teardown once an add-on with property callbacks was
# registered: leave as the shipped extension's command line does.
importlib.import_module(f"{MODULE}.ellimann_addon.blender.services.teardown").exit_with(0)
