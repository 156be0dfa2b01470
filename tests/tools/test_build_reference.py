"""The shipped reference data is what its build tool makes from ../shared/refmodels today.

A change to fitting, cleaning or refinement that moves the reference mannequins fails here until
``python -m tools.build_reference`` is run again and its output committed (JSON, .blend, docs).
"""

import pytest

from tools import build_reference


@pytest.mark.slow
def test_shipped_reference_data_and_docs_are_the_build_tools_output(capsys):
    status = build_reference.main(["--check", "--no-blend"])
    out = capsys.readouterr().out
    assert status == 0, out[out.index("built in"):]
    assert "identical to the files in" in out
