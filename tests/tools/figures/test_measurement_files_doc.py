"""tools/figures/measurement_files_doc.py: --check passes on the page as committed and fails on one whose tables
differ."""

from tools.figures import measurement_files_doc


def test_check_passes_and_fails(tmp_path, monkeypatch, capsys):
    assert measurement_files_doc.main(["--check"]) == 0
    page = tmp_path / "page.md"
    page.write_text(measurement_files_doc.PAGE.read_text().replace("| `bust_circ` | **Br** |", "| `bust_circ` | He |"))
    monkeypatch.setattr(measurement_files_doc, "PAGE", page)
    assert measurement_files_doc.main(["--check"]) == 1
    assert "differs" in capsys.readouterr().out
    assert measurement_files_doc.main([]) == 0 and measurement_files_doc.main(["--check"]) == 0
