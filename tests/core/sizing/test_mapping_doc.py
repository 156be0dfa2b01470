"""docs/formats/measurement_files.md's mapping tables are generated from core.sizing.names: the page matches the
code, and every mapping names one of ElliMann's eleven, a predictor or nothing."""

import pathlib

from ellimann_addon.core.sizing.mapping_doc import BEGIN, END, mapping_markdown, replace_tables
from ellimann_addon.core.sizing.names import CHART, FREESEWING, FREESEWING_KNOWN, KEYS, PREDICTORS, SEAMLY, SEAMLY_KNOWN

PAGE = pathlib.Path(__file__).resolve().parents[3] / "docs" / "formats" / "measurement_files.md"


def test_the_page_holds_the_tables_the_code_makes():
    page = PAGE.read_text(encoding="utf-8")
    assert replace_tables(page) == page, "run python -m tools.figures.measurement_files_doc"


def test_every_mapping_row_is_on_the_page_with_its_reason():
    text = mapping_markdown()
    assert text.startswith(BEGIN) and text.endswith(END)
    for table in (SEAMLY, FREESEWING, CHART):
        for row in table.values():
            if row.name not in KEYS:
                assert f"| `{row.name}` |" in text and row.why in text


def test_mappings_name_known_names_and_known_targets():
    assert set(SEAMLY) <= set(SEAMLY_KNOWN) and len(SEAMLY_KNOWN) == len(set(SEAMLY_KNOWN)) == 246
    assert set(FREESEWING) <= set(FREESEWING_KNOWN)
    for table in (SEAMLY, FREESEWING, CHART):
        assert all(row.key is None or row.key in KEYS or row.key in PREDICTORS for row in table.values())
    for table in (SEAMLY, FREESEWING):  # one file name per ElliMann measurement: the writers' choice is unique
        used = [row.key for row in table.values() if row.key in KEYS]
        assert len(used) == len(set(used))
