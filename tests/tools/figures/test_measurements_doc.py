"""tools/figures/measurements_doc.py: the table of docs/measurements.md is core.measurements.TABLE's; --check fails
on a page whose table differs."""

from tools.figures import measurements_doc


def test_the_page_s_table_is_the_code_s_and_check_can_fail(tmp_path, monkeypatch, capsys):
    assert measurements_doc.main(["--check"]) == 0
    page = tmp_path / "page.md"
    page.write_text(measurements_doc.PAGE.read_text().replace("| `neck` | Neck girth |", "| `neck` | Neck |"))
    monkeypatch.setattr(measurements_doc, "PAGE", page)
    assert measurements_doc.main(["--check"]) == 1
    assert "differs" in capsys.readouterr().out
    assert measurements_doc.main([]) == 0 and measurements_doc.main(["--check"]) == 0
