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


def core_modules():
    """Every module under core, dotted (packages too)."""
    names = []
    for path in sorted(CORE.rglob("*.py")):
        parts = path.relative_to(CORE.parents[1]).with_suffix("").parts
        names.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return names


def test_importing_every_core_module_loads_no_blender_module():
    modules = core_modules()
    code = (
        "import sys, importlib\n"
        f"for m in {modules!r}: importlib.import_module(m)\n"
        f"print(sorted(set(sys.modules) & set({sorted(BLENDER_MODULES)!r})))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=CORE.parents[1])
    assert out.stdout.strip() == "[]"


def test_importing_every_core_module_loads_no_package_blender_lacks():
    """Blender bundles numpy, not scipy (nor the dev tools): the core, the reference builder included, needs none."""
    modules = core_modules()
    code = (
        "import sys, importlib\n"
        f"for m in {modules!r}: importlib.import_module(m)\n"
        "loaded = {name.partition('.')[0] for name in sys.modules}\n"
        "print(sorted(loaded & {'scipy', 'pytest', 'hypothesis', 'mujoco'}))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=CORE.parents[1])
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
                base = package[: len(package) - (node.level - 1)] if node.level > 1 else package
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            found.append(module)
            found += [f"{module}.{alias.name}" for alias in node.names]  # `from .. import blender`
    return found


def test_core_imports_nothing_of_the_blender_layer_relatively_either():
    offenders = [
        f"{p.relative_to(PACKAGE)}: {m}"
        for p in CORE.rglob("*.py")
        for m in resolved_imports(p)
        if m == "ellimann_addon.blender" or m.startswith("ellimann_addon.blender.")
    ]
    assert offenders == []


def test_blender_bridge_and_services_import_no_feature():
    """bridge/ (objects <-> core) and services/ (building, writing) are below the features: they never import one."""
    offenders = [
        f"{p.relative_to(PACKAGE)}: {m}"
        for folder in ("bridge", "services")
        for p in (BLENDER / folder).rglob("*.py")
        for m in resolved_imports(p)
        if m.startswith(("ellimann_addon.blender.features", "ellimann_addon.blender.registry"))
    ]
    assert offenders == []
    offenders = [
        f"{p.relative_to(PACKAGE)}: {m}"
        for p in (BLENDER / "bridge").rglob("*.py")
        for m in resolved_imports(p)
        if m.startswith("ellimann_addon.blender.services")
    ]
    assert offenders == []


def test_the_layering_check_sees_a_relative_import_into_blender():
    probe = CORE / "probe.py"  # never written: its source is given
    found = resolved_imports(probe, "from ..blender import registry\nfrom ..blender.features import base\n")
    assert "ellimann_addon.blender.registry" in found and "ellimann_addon.blender.features" in found
    assert resolved_imports(CORE / "sub" / "probe.py", "from ...blender import ids\n") == [
        "ellimann_addon.blender",
        "ellimann_addon.blender.ids",
    ]


# The core's house plan: shared modules at its top, then one package per domain. A package imports the shared
# modules and the packages on floors below its own, never one beside or above it (so the imports form one
# direction and no cycle can arise).
SHARED = {"constants", "errors", "files", "measurements", "option_table", "settings"}
FLOORS = {
    "geometry": 1,
    "measure": 2,
    "mannequin": 3,
    "synthesis": 4,
    "pose": 4,
    "fitting": 5,
    "skin": 5,
    "sizing": 5,
    "body": 5,
    "formats": 6,
    "drape": 6,
    "job": 7,
}


def core_unit(dotted):
    """The shared module or domain package a dotted name under ellimann_addon.core belongs to (None: outside)."""
    parts = dotted.split(".")
    if parts[:2] != ["ellimann_addon", "core"] or len(parts) < 3:
        return None
    return parts[2]


def test_the_core_is_shared_modules_and_domain_packages_only():
    units = {p.stem for p in CORE.glob("*.py")} | {p.name for p in CORE.iterdir() if (p / "__init__.py").is_file()}
    assert units - {"__init__"} == SHARED | set(FLOORS)


def test_each_core_package_imports_only_floors_below_it():
    offenders = []
    for path in CORE.rglob("*.py"):
        here = core_unit(".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts))
        for module in resolved_imports(path):
            there = core_unit(module)
            if there is None or there == here or there in SHARED:
                continue
            if here in SHARED or FLOORS[there] >= FLOORS[here]:
                offenders.append(f"{path.relative_to(CORE)} ({here}) imports {module} ({there})")
    assert offenders == []


def test_each_core_package_init_names_every_module_it_holds():
    """An ``__init__`` is a table of contents, a line per module (``- name: what it holds``), and imports nothing
    (importing a package loads none of its modules)."""
    for package in FLOORS:
        tree = ast.parse((CORE / package / "__init__.py").read_text())
        doc = ast.get_docstring(tree) or ""
        listed = {line[2:].partition(":")[0] for line in doc.splitlines() if line.startswith("- ")}
        held = {p.stem for p in (CORE / package).glob("*.py")} - {"__init__"}
        assert listed == held, package
        assert not [n for n in tree.body if isinstance(n, (ast.Import, ast.ImportFrom))], package


def test_no_module_in_the_package_is_over_500_lines():
    long = [
        f"{p.relative_to(PACKAGE)}: {n}" for p in PACKAGE.rglob("*.py") if (n := len(p.read_text().splitlines())) > 500
    ]
    assert long == []


def test_no_private_name_is_imported_across_modules():
    offenders = []
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level:
                offenders += [
                    f"{path.relative_to(PACKAGE)}: {a.name}"
                    for a in node.names
                    if a.name.startswith("_") and not a.name.startswith("__")
                ]
    assert offenders == []


def dotted_modules(folders):
    """{dotted name: path} of every module under ``folders`` (packages by their ``__init__``)."""
    modules = {}
    for folder in folders:
        for path in folder.rglob("*.py"):
            parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
            modules[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return modules


def module_graph(sources=None, folders=(PACKAGE,)):
    """Each module of the package (or of ``folders``) -> the modules among them it imports, at its top or inside a
    function (a lazy import is an edge too). ``sources``: {dotted name: source text} read instead of those modules'
    files."""
    sources = sources or {}
    graph = {name: set(resolved_imports(path, sources.get(name))) for name, path in dotted_modules(folders).items()}

    def edges(name, deps):
        # A module's own packages are loaded before it: importing a submodule of one (``from .. import ids``) adds
        # no edge to the package, but importing what its __init__ defines (``from .. import register``) runs
        # that package's code, lazy imports and all: an edge.
        used = {m.rsplit(".", 1)[0] for m in deps if m not in graph and "." in m}
        return {m for m in deps if m in graph and m != name and (not name.startswith(m + ".") or m in used)}

    return {name: edges(name, deps) for name, deps in graph.items()}


def find_cycle(graph):
    """One import cycle as a list of modules, or []."""
    state = {}

    def visit(node, trail):
        state[node] = "open"
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                return trail[trail.index(nxt) :] + [nxt]
            if nxt not in state and (found := visit(nxt, trail + [nxt])):
                return found
        state[node] = "done"
        return []

    for node in sorted(graph):
        if node not in state and (found := visit(node, [node])):
            return found
    return []


def test_no_import_cycle_in_the_package():
    assert find_cycle(module_graph()) == []


REPOSITORY = PACKAGE.parent
DEV_FOLDERS = tuple(REPOSITORY / name for name in ("tools", "bench", "devkit"))


def test_no_import_cycle_anywhere_tools_bench_and_devkit_included():
    assert find_cycle(module_graph(folders=(PACKAGE, *DEV_FOLDERS))) == []


def test_every_import_of_tools_bench_or_devkit_names_one_of_their_modules():
    """tools/, bench/ and devkit/ are imported by path from the repository root (tests, benchmarks, ``python -m``): a
    module moved without its importers following fails here, lazy imports included, not when that code first runs."""
    modules = dotted_modules(DEV_FOLDERS)
    importers = [*modules.values(), *(REPOSITORY / "tests").rglob("*.py")]
    unknown = [
        f"{path.relative_to(REPOSITORY)}: {name}"
        for path in importers
        for name in resolved_imports(path)
        if name.split(".")[0] in {"tools", "bench", "devkit"}
        and name not in modules
        and name.rsplit(".", 1)[0] not in modules  # ``from tools.x import name``: a name of a module
    ]
    assert unknown == []


def test_the_cycle_check_sees_a_lazy_import_of_a_parent_package_s_code():
    """The command line once registered the whole add-on to write a .glb (``from .. import register`` inside a
    function), which registered the Blender command, which imports the command line: a cycle through the parent
    package's code that a check dropping every import of a module's own packages did not see."""
    lazy = "def write():\n    from .. import register\n\n    register()\n"
    graph = module_graph({"ellimann_addon.cli.writing": lazy})
    cycle = find_cycle(graph)
    assert "ellimann_addon.cli.writing" in cycle and "ellimann_addon.blender.cli_command" in cycle, cycle


def test_the_cycle_check_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) == []


def test_every_folder_of_the_package_has_a_one_line_readme():
    folders = [PACKAGE] + [p for p in PACKAGE.rglob("*") if p.is_dir() and p.name != "__pycache__"]
    missing = [str(f.relative_to(PACKAGE.parent)) for f in folders if not (f / "README.md").is_file()]
    assert missing == []
    long = [str(f.relative_to(PACKAGE.parent)) for f in folders if len((f / "README.md").read_text().splitlines()) != 1]
    assert long == []


def test_every_folder_of_tools_devkit_tests_and_bench_has_a_one_line_readme():
    """The package's rule (above) for the folders around it: each README.md is one line saying what the folder holds."""
    folders = [
        folder
        for root in ("tools", "devkit", "tests", "bench")
        for folder in [REPOSITORY / root, *(REPOSITORY / root).rglob("*")]
        if folder.is_dir()
        and not any(p == "__pycache__" or p.startswith(".") for p in folder.relative_to(REPOSITORY).parts)
    ]
    missing = [str(f.relative_to(REPOSITORY)) for f in folders if not (f / "README.md").is_file()]
    assert missing == []
    long = [str(f.relative_to(REPOSITORY)) for f in folders if len((f / "README.md").read_text().splitlines()) != 1]
    assert long == []


def test_the_floors_are_written_once_here_and_said_alike_everywhere():
    """FLOORS (above) is the house plan; each package's __init__ says its floor ("(floor N") and
    docs/architecture.md's tree gives it beside the package's name: a test, not a reader, finds one that moved."""
    import re

    architecture = (PACKAGE.parent / "docs" / "architecture.md").read_text()
    for package, floor in FLOORS.items():
        doc = ast.get_docstring(ast.parse((CORE / package / "__init__.py").read_text())) or ""
        assert re.search(rf"\(floor {floor}\b", " ".join(doc.split())), package
        assert re.search(rf"^\s+{package}/\s+{floor}\s", architecture, re.M), package
