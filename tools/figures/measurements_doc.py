"""Rewrite the table of docs/measurements.md from ``core.measurements.TABLE`` (the code is the source):
``python -m tools.figures.measurements_doc`` (``--check``: exit 1 when the page differs)."""

import argparse
import pathlib
import sys

from ellimann_addon.core.files import atomic_write_text
from ellimann_addon.core.measurements import TABLE

PAGE = pathlib.Path(__file__).resolve().parents[2] / "docs" / "measurements.md"
START = "<!-- the table: python -m tools.figures.measurements_doc -->"
END = "<!-- end of the table -->"


def table():
    """The page's table, a row per measurement."""
    lines = [
        "| key | label | kind | where it is taken | a request may ask (cm) | ISO 20685 allowance (cm) "
        "| the panel starts at |",
        "|---|---|---|---|---|---|---|",
    ]
    for row in TABLE:
        low, high = row.limits
        start = "the set's Average" if row.default is None else f"{row.default:g} cm"
        kind = "girth" if row.girth else "length"
        lines.append(
            f"| `{row.key}` | {row.label} | {kind} | {row.where} | {low:g} to {high:g} | {row.allowance:g} | {start} |"
        )
    return "\n".join(lines)


def rewritten(page):
    """``page`` with the text between START and END made from the table."""
    head, _, rest = page.partition(START)
    _, _, tail = rest.partition(END)
    return f"{head}{START}\n{table()}\n{END}{tail}"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--check", action="store_true", help="only check that the page matches the code")
    args = parser.parse_args(argv)
    page = PAGE.read_text(encoding="utf-8")
    wanted = rewritten(page)
    if args.check:
        if wanted != page or START not in page:
            print(f"{PAGE} differs from core.measurements.TABLE: run python -m tools.figures.measurements_doc")
            return 1
        return 0
    if wanted != page:
        atomic_write_text(PAGE, wanted)
    return 0


if __name__ == "__main__":
    sys.exit(main())
