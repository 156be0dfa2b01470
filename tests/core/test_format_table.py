"""The format table (core/formats/table.py): every row names a writer that exists and a whole-file check that
core.files.incomplete makes, and every format ElliMann defines has its page in docs/formats/ naming its code."""

import ast
import importlib
import pathlib

import pytest

from ellimann_addon.core import files
from ellimann_addon.core.formats.table import BATCH_FILE, FORMATS, WHOLE_FILE_CHECK

ROOT = pathlib.Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "ellimann_addon"
ROWS = [*FORMATS.values(), BATCH_FILE]


def defined(dotted):
    """Whether ``dotted`` (under ellimann_addon) names a function or class: imported for the core, read from the
    source for the Blender layer (which needs bpy to import)."""
    parts = dotted.split(".")
    for split in range(len(parts) - 1, 0, -1):
        path = PACKAGE.joinpath(*parts[:split]).with_suffix(".py")
        if path.is_file():
            module, names = parts[:split], parts[split:]
            break
    else:
        return False
    if module[0] == "core":
        target = importlib.import_module("ellimann_addon." + ".".join(module))
        for name in names:
            target = getattr(target, name, None)
        return callable(target)
    tree = ast.parse(path.read_text())
    for name in names:
        found = [n for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef)) and n.name == name]
        if not found:
            return False
        tree = found[0]
    return True


@pytest.mark.parametrize("row", ROWS, ids=[row.name for row in ROWS])
def test_each_row_names_its_writer_and_its_whole_file_check(row):
    assert defined(row.written_by), row.written_by
    assert row.extension in files.CHECKED_KINDS and row.whole_file
    assert defined(WHOLE_FILE_CHECK)


def test_the_name_check_can_fail():
    assert not defined("core.formats.obj.write_nothing") and not defined("blender.services.files.no_such")


PAGES = {  # a page per format ElliMann defines, and code each must name
    "mannequin_json.md": ["Mannequin.save", "Mannequin.load", "posed_files.write_posed", "read_pose"],
    "gltf_extras.md": ["export_gltf", "read_glb_json", "core.files.incomplete"],
    "reference_set.md": ["write_reference_set", "read_manifest", "load_reference_set", "references check"],
    "batch_npz.md": ["BatchFileWriter", "write_batch_file", "read_batch_file", "load_batch_file"],
    "batch_csv.md": ["MeasurementsCsv", "Report"],
    "body_space.md": ["BodySpace.save", "read_body_space", "space_from_meshes", "tools.add_body_space"],
}


@pytest.mark.parametrize("page", PAGES)
def test_each_format_page_names_its_reader_writer_and_check_and_is_linked(page):
    text = (ROOT / "docs" / "formats" / page).read_text()
    assert "Whole-file check" in text or "whole-file check" in text.lower(), page
    for name in PAGES[page]:
        assert name in text, (page, name)
    index = (ROOT / "docs" / "formats" / "README.md").read_text()
    assert f"({page})" in index
    for doc in ("README.md", "docs/architecture.md"):
        assert "docs/formats" in (ROOT / doc).read_text() or "formats/README.md" in (ROOT / doc).read_text(), doc
