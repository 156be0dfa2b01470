"""``ellimann demo``: the ten mannequins of the paper's Table 2.5 as .blend and .json, a report and a Workbench
line-up (Blender)."""

import os
import sys

from ..core.constants import TABLE_2_5
from ..core.measure.tailor import as_dict
from ..core.measurements import MEASUREMENTS
from ..core.synthesis.misses import missed_text, request_misses
from ..core.synthesis.options import PAPER
from . import arguments, output, reporting, writing
from .output import PROG


def add_parser(commands):
    demo = commands.add_parser(
        "demo",
        help="the paper's ten Table 2.5 mannequins, a report and a line-up",
        description="Synthesize the ten mannequins of the paper's Table 2.5 into DIR: "
        ".blend and .json files, report.csv, report.md and lineup.png.",
    )
    demo.add_argument("-o", "--output", required=True, metavar="DIR")
    demo.add_argument("--no-picture", dest="picture", action="store_false", help="skip the line-up render")
    arguments.add_synthesis_options(demo)
    demo.set_defaults(run=run, blender=needs_blender)


def needs_blender(args):
    """What needs Blender in this command: its .blend files (and the line-up picture)."""
    return "the demo (.blend files and a line-up picture)"


def run(args):
    from ..core.formats.table import check_outputs
    from ..core.job.result import Result
    from ..core.synthesis.synthesize import synthesize_batch

    reference = arguments.references(args)
    out = args.output
    writing.output_folder(out, "demo")
    result = synthesize_batch(reference, [list(row) for row in TABLE_2_5], arguments.synthesis_options(args))
    rows, mannequins, missed = [], [], 0
    for i in range(len(result)):
        name = f"table_2_5_{i + 1:02d}"
        mannequin = result.mannequin(i)
        paths = [os.path.join(out, f"{name}.{kind}") for kind in ("blend", "json")]
        writing.write(Result(mannequin, as_dict(result.measured[i])), check_outputs(paths), args.cushions)
        misses = request_misses(as_dict(result.measured[i]), result.requests[i], mode=args.mode)
        if misses:
            missed += 1
            output.say(f"{PROG} demo: {name}: warning: {missed_text(misses)}")
        rows.append(
            reporting.report_row(
                i + 1,
                name,
                "missed" if misses else "ok",
                "; ".join([mannequin.name] + ([missed_text(misses)] if misses else [])),
                result.requests[i],
                result.measured[i],
                paths,
            )
        )
        mannequins.append(mannequin)
        output.say(f"{PROG} demo: wrote {name} ({mannequin.name})")
    for name, text in (
        ("report.csv", reporting.report_csv(rows)),
        ("report.md", report_markdown(result, reference, args)),
    ):
        writing.write_text(os.path.join(out, name), text)
    if args.picture:
        from ..blender.services.render import render_lineup

        with writing.writing(os.path.join(out, "lineup.png")):
            render_lineup(
                mannequins,
                os.path.join(out, "lineup.png"),
                labels=[f"({i + 1})" for i in range(len(rows))],
                cushions=args.cushions,
            )
    error = result.relative_error()
    output.say(
        f"{PROG} demo: {len(rows)} mannequins in {out} ({args.mode}); m_T error mean {error.mean():.3f}%, "
        f"max {error.max():.3f}%; see {os.path.join(out, 'report.md')}",
        file=sys.stdout,
    )
    return output.MISSED if missed else 0


LINEUP_NOTE = (
    "`lineup.png`: the ten seen from the front, labelled (1)-(10) as the rows above. Each piece is coloured by the "
    "side of the body it is on: the body's right blue, its left pink, the central pieces grey (seen from the front a "
    "mannequin is blue on the viewer's left), as in Blender's viewport (`blender.bridge.convert.SIDE_COLORS`)."
)


def report_markdown(result, reference, args):
    """Requested vs m_T per mannequin, and the error summary beside the paper's IDW."""
    from ..core.synthesis.synthesize import synthesize_batch

    paper = arguments.synthesis_options(args) == PAPER
    idw = result if paper else synthesize_batch(reference, result.requests, PAPER)
    error, idw_error = result.relative_error(), idw.relative_error()
    lines = [
        "# ElliMann demo: the ten mannequins of the paper's Table 2.5",
        "",
        f"Mode `{args.mode}`, IDW `{args.normalize}`, distance `{args.metric}`, p = {args.power:g}. Reference "
        "Mannequins: "
        f"{', '.join(reference.names)} ({len(reference.topology)} ellipsoids each).",
        "",
        "Requested measurements and m_T of the synthesized mannequin (cm); largest relative error (%) of this "
        "mode and of the paper's IDW (normalize `none`, distance `raw`, p = 2).",
        "",
        "| # | "
        + " | ".join(MEASUREMENTS)
        + " | "
        + " | ".join(f"m_T {k}" for k in MEASUREMENTS)
        + f" | max error % ({args.mode}) | max error % (paper IDW) |",
        "|---|" + "---:|" * (2 * len(MEASUREMENTS) + 2),
    ]
    for i in range(len(result)):
        cells = [f"{v:g}" for v in result.requests[i]] + [f"{v:.2f}" for v in result.measured[i]]
        cells += [f"{error[i].max():.3f}", f"{idw_error[i].max():.3f}"]
        lines.append(f"| {i + 1} | " + " | ".join(cells) + " |")
    lines += [
        "",
        "Relative error (%) over the ten:",
        "",
        "| | " + " | ".join(MEASUREMENTS) + " |",
        "|---|" + "---:|" * len(MEASUREMENTS),
    ]
    for label, values in (
        (f"mean, {args.mode}", error.mean(axis=0)),
        (f"max, {args.mode}", error.max(axis=0)),
        ("mean, paper IDW", idw_error.mean(axis=0)),
        ("max, paper IDW", idw_error.max(axis=0)),
    ):
        if paper and label.endswith("IDW"):
            continue
        lines.append(f"| {label} | " + " | ".join(f"{v:.3f}" for v in values) + " |")
    if args.picture:
        lines += ["", LINEUP_NOTE]
    return "\n".join(lines) + "\n"
