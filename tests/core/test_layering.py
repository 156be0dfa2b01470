"""The core is pure numpy: no Blender module may be imported anywhere below ellimann_addon/core."""

import ast
import pathlib
import subprocess
import sys

CORE = pathlib.Path(__file__).resolve().parents[2] / "ellimann_addon" / "core"
BLENDER_MODULES = {"bpy", "bmesh", "mathutils", "bpy_extras", "gpu", "bl_math"}


def test_core_source_imports_no_blender_module():
    offenders = []
    for path in CORE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            names = []
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            offenders += [f"{path.name}: {n}" for n in names if n.split(".")[0] in BLENDER_MODULES]
    assert offenders == []


def test_importing_every_core_module_loads_no_blender_module():
    modules = [p.stem for p in CORE.glob("*.py") if p.stem != "__init__"]
    code = (
        "import sys, importlib\n"
        f"for m in {modules!r}: importlib.import_module('ellimann_addon.core.' + m)\n"
        f"print(sorted(set(sys.modules) & set({sorted(BLENDER_MODULES)!r})))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=CORE.parents[1])
    assert out.stdout.strip() == "[]"


def test_importing_every_core_module_loads_no_package_blender_lacks():
    """Blender bundles numpy, not scipy (nor the dev tools): the core, the reference builder included, needs none."""
    modules = [p.stem for p in CORE.glob("*.py") if p.stem != "__init__"]
    code = (
        "import sys, importlib\n"
        f"for m in {modules!r}: importlib.import_module('ellimann_addon.core.' + m)\n"
        "loaded = {name.partition('.')[0] for name in sys.modules}\n"
        "print(sorted(loaded & {'scipy', 'pytest', 'hypothesis', 'mujoco'}))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=CORE.parents[1])
    assert out.stdout.strip() == "[]"


def test_core_uses_only_relative_imports_for_project_modules():
    for path in CORE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                assert not node.module.startswith("ellimann"), f"{path.name} imports {node.module} absolutely"


PACKAGE = CORE.parent
BLENDER = PACKAGE / "blender"


def resolved_imports(path, text=None):
    """Every module ``path`` (its source ``text``, default: read) imports, relative imports resolved to dotted
    names under ellimann_addon."""
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    package = parts if path.name == "__init__.py" else parts[:-1]
    if package and package[-1] == "__init__":
        package = package[:-1]
    found = []
    for node in ast.walk(ast.parse(path.read_text() if text is None else text, filename=str(path))):
        if isinstance(node, ast.Import):
            found += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - (node.level - 1)] if node.level > 1 else package
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            found.append(module)
            found += [f"{module}.{alias.name}" for alias in node.names]  # `from .. import blender`
    return found


def test_core_imports_nothing_of_the_blender_layer_relatively_either():
    offenders = [f"{p.relative_to(PACKAGE)}: {m}" for p in CORE.rglob("*.py") for m in resolved_imports(p)
                 if m == "ellimann_addon.blender" or m.startswith("ellimann_addon.blender.")]
    assert offenders == []


def test_blender_bridge_and_services_import_no_feature():
    """bridge/ (objects <-> core) and services/ (building, writing) are below the features: they never import one."""
    offenders = [f"{p.relative_to(PACKAGE)}: {m}" for folder in ("bridge", "services")
                 for p in (BLENDER / folder).rglob("*.py") for m in resolved_imports(p)
                 if m.startswith(("ellimann_addon.blender.features", "ellimann_addon.blender.registry"))]
    assert offenders == []
    offenders = [f"{p.relative_to(PACKAGE)}: {m}" for p in (BLENDER / "bridge").rglob("*.py")
                 for m in resolved_imports(p) if m.startswith("ellimann_addon.blender.services")]
    assert offenders == []


def test_the_layering_check_sees_a_relative_import_into_blender():
    probe = CORE / "probe.py"  # never written: its source is given
    found = resolved_imports(probe, "from ..blender import registry\nfrom ..blender.features import base\n")
    assert "ellimann_addon.blender.registry" in found and "ellimann_addon.blender.features" in found
    assert resolved_imports(CORE / "sub" / "probe.py", "from ...blender import ids\n") == [
        "ellimann_addon.blender", "ellimann_addon.blender.ids"]
