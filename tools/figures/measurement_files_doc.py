"""Rewrite docs/formats/measurement_files.md's mapping tables from core.sizing.names (the code is the source):
``python -m tools.figures.measurement_files_doc`` (``--check``: exit 1 when the page differs)."""

import argparse
import pathlib
import sys

from ellimann_addon.core.files import atomic_write_text
from ellimann_addon.core.sizing.mapping_doc import replace_tables

PAGE = pathlib.Path(__file__).resolve().parents[2] / "docs" / "formats" / "measurement_files.md"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--check", action="store_true", help="only check that the page matches the code")
    args = parser.parse_args(argv)
    page = PAGE.read_text(encoding="utf-8")
    wanted = replace_tables(page)
    if args.check:
        if wanted != page:
            print(f"{PAGE} differs from core.sizing.names: run python -m tools.figures.measurement_files_doc")
            return 1
        return 0
    if wanted != page:
        atomic_write_text(PAGE, wanted)
    return 0


if __name__ == "__main__":
    sys.exit(main())
