"""The format table (core/formats/table.py): every row has a whole-file check that core.files.incomplete makes and
a writer (the core's rows here, Blender's bound by the Blender layer), a path's format is decided by its extension
alone, and every format ElliMann defines has its page in docs/formats/ naming its code."""

import pathlib
import sys

import pytest

from ellimann_addon.core import files
from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.formats import table
from ellimann_addon.core.formats.table import BATCH_FILE, BLENDER_FORMATS, CORE_FORMATS, FORMATS

ROOT = pathlib.Path(__file__).resolve().parents[3]
PACKAGE = ROOT / "ellimann_addon"
ROWS = [*FORMATS.values(), BATCH_FILE]


@pytest.mark.parametrize("row", ROWS, ids=[row.name for row in ROWS])
def test_each_row_has_its_whole_file_check_and_the_core_s_rows_their_writer(row):
    assert row.extension in files.CHECKED_KINDS and row.whole_file
    if row.name in CORE_FORMATS:
        assert callable(row.write) and row.writer() is row.write
    elif row.name in BLENDER_FORMATS and "ellimann_addon.blender.services.writers" not in sys.modules:
        with pytest.raises(ElliMannError, match=f"writing a .{row.extension} file needs Blender"):
            row.writer()  # the Blender layer binds it when loaded (tests/blender/services/test_export_gltf.py)


def test_a_path_s_format_is_decided_by_its_extension_once_and_refused_in_one_line():
    formats = table.check_outputs(["a.JSON", "b.xml", "c.glb"])
    assert [kind.name for kind in formats.values()] == ["json", "mjcf", "glb"]
    with pytest.raises(ElliMannError, match=r"'d\.stl': an output file must end in \.blend, \.glb, \.obj, \.json, "):
        table.check_outputs(["d.stl"])
    with pytest.raises(ElliMannError, match="--pose walk is an animation and a .obj file holds none; write .blend"):
        table.check_outputs(["e.obj"], "walk")
    assert table.format_named("XML") is FORMATS["mjcf"] and table.format_named("npz") is None
    assert table.format_named("npz", batch=True) is BATCH_FILE
    assert table.listing(what="name") == "blend, glb, obj, json, mjcf (xml), fbx"
    assert table.listing().endswith(".json, .xml (MJCF) or .fbx")


PAGES = {  # a page per format ElliMann defines, and code each must name
    "mannequin_json.md": ["Mannequin.save", "Mannequin.load", "posed_files.write_posed", "read_pose"],
    "gltf_extras.md": ["export_gltf", "read_glb_json", "core.files.incomplete"],
    "reference_set.md": ["write_reference_set", "read_manifest", "load_reference_set", "references check"],
    "batch_npz.md": ["BatchFileWriter", "write_batch_file", "read_batch_file", "load_batch_file"],
    "batch_csv.md": ["MeasurementsCsv", "Report"],
    "body_space.md": ["BodySpace.save", "read_body_space", "space_from_meshes", "tools.shipped.add_body_space"],
    "fbx_avatar.md": ["write_fbx", "write_avatar_files", "remeasure", "core.files.incomplete", "ellimann sizes"],
    "measurement_files.md": ["read_measurement_file", "write_vit", "ellimann sizes", "--write-measurements"],
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
