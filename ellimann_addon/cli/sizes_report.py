"""The report of ``ellimann sizes``: per size and measurement, what the file asks (given, or predicted from the
survey with the spread left), what the size's skin measures and the difference, all in the file's own unit; the
rows that failed with their one line. As DIR/report.csv (a row per size and measurement, a row per failed size) and
DIR/report.md."""

import csv
import io
import math
import os

from ..core.measurements import ALL_MEASUREMENTS
from .output import printable
from .reporting import cell

FORMAT_NAMES = {
    "vit": "Seamly2D / Valentina individual measurements",
    "vst": "Seamly2D / Valentina multisize table",
    "freesewing": "FreeSewing measurements set",
    "chart": "size chart",
}
COLUMNS = (
    "size",
    "file",
    "status",
    "measurement",
    "name_in_file",
    "source",
    "unit",
    "requested",
    "measured",
    "difference",
    "predicted_sd",
    "fbx_measured",
    "fbx_triangles",
    "skin",
    "message",
)


class Made:
    """What came of one row: its ``row`` (core.sizing.rows.SizeRow), file ``name``, the job's ``result``
    (core.job.result.Result) and ``paths``, the FBX ``avatars`` written (blender.services.fbx.FbxAvatar), or
    its one-line ``error``."""

    def __init__(self, row, name):
        self.row, self.name = row, name
        self.result, self.paths, self.avatars, self.error = None, [], [], None

    def fail(self, line):
        self.error = line

    def done(self, result, paths, avatars):
        self.result, self.paths, self.avatars = result, paths, list(avatars)

    @property
    def status(self):
        if self.error is not None:
            return "error"
        return "missed" if self.result.missed else "ok"

    def warnings(self):
        """Its warnings (the row's, the job's) and what it missed, in words."""
        said = [*self.row.warnings, *self.result.warnings]
        if self.result.missed:
            said.append(self.result.missed_text())
        return said

    def lines(self):
        """What to say of it (after "ellimann sizes: "): its failure (which names the file and the row), or its
        warnings and what it missed."""
        if self.error is not None:
            return [f"failed: {self.error}"]
        return [f"size {self.row.label}: warning: {line}" for line in self.warnings()]

    def measured(self):
        """{key: cm} its skin measures (its pieces' without a skin)."""
        return self.result.shown()


class Report:
    """The run's report: the file ``read`` (core.sizing.rows.MeasurementFile), the ``reference`` set, the ``skin``
    asked, every row's :class:`Made` in the file's order and the ``formats`` written; ``picture``: the line-up's
    path (None: skipped)."""

    def __init__(self, read, reference, skin, made, formats):
        self.read, self.reference, self.skin, self.made, self.formats = read, reference, skin, made, formats
        self.picture = None
        self.interrupted = False  # Ctrl-C: the sizes after the last made are not in the report

    def count(self, *statuses):
        return sum(m.status in statuses for m in self.made)

    def skin_settings(self):
        """How the skins were made (``skin``: the command's, its kind decided; a row may fall back to the skin over
        the pieces, which its warnings say)."""
        return self.skin

    def entries(self, made):
        """[(key, requested, measured, difference, source, name in the file, sd, FBX measured)] of a made row, in
        the file's unit of each measurement (sd and the FBX's: None where there is none)."""
        row, measured = made.row, made.measured()
        fbx = made.avatars[0].measured if made.avatars else {}
        unit = self.read.in_file_unit
        found = []
        for key in ALL_MEASUREMENTS:
            if key not in row.values or (key not in row.request() and key not in row.extra()):
                continue
            asked, got = unit(key, row.values[key]), measured.get(key, math.nan)
            got = unit(key, got) if math.isfinite(got) else math.nan
            if key in row.predicted:
                source, name, sd = "predicted", "", unit(key, row.predicted[key][1])
            else:
                source, name, sd = "given", row.given[key][0] if key in row.given else "", None
            on_fbx = unit(key, fbx[key]) if key in fbx and math.isfinite(fbx[key]) else None
            found.append((key, asked, got, got - asked, source, name, sd, on_fbx))
        return found

    def worst(self):
        """(|difference|, size, key) of the largest difference in the run (None when nothing was made)."""
        found = [
            (abs(entry[3]), made.row.label, entry[0])
            for made in self.made
            if made.result is not None
            for entry in self.entries(made)
            if math.isfinite(entry[3])
        ]
        return max(found) if found else None

    def worst_text(self):
        worst = self.worst()
        if worst is None:
            return "none (nothing made)"
        value, label, key = worst
        return f"{value:.3f} {self.read.unit_of(key)} (size {label}, {key})"

    def csv(self):
        stream = io.StringIO()
        writer = csv.DictWriter(stream, fieldnames=COLUMNS, lineterminator="\n")
        writer.writeheader()
        for made in self.made:
            base = {"size": cell(made.row.label), "file": cell(made.name), "status": made.status}
            if made.result is None:
                writer.writerow({**base, "message": cell(made.error)})
                continue
            avatar = made.avatars[0] if made.avatars else None
            for key, asked, got, off, source, name, sd, on_fbx in self.entries(made):
                writer.writerow(
                    {
                        **base,
                        "measurement": key,
                        "name_in_file": cell(name),
                        "source": source,
                        "unit": self.read.unit_of(key),
                        "requested": f"{asked:.4f}",
                        "measured": f"{got:.4f}",
                        "difference": _signed(off, 4),
                        "predicted_sd": "" if sd is None else f"{sd:.4f}",
                        "fbx_measured": "" if on_fbx is None else f"{on_fbx:.4f}",
                        "fbx_triangles": "" if avatar is None else str(avatar.triangles),
                        "skin": made.result.skin.settings.describe() if made.result.skin is not None else "",
                        "message": cell("; ".join(made.warnings())),
                    }
                )
        return stream.getvalue()

    def markdown(self):
        read = self.read
        units = sorted(set(read.unit_of(key) for key in ALL_MEASUREMENTS))
        sex = read.sex or "not said (read as female)"
        made = self.count("ok", "missed")
        lines = [
            f"# ElliMann sizes: {os.path.basename(read.path)}",
            "",
            f"- file: `{read.path}` ({FORMAT_NAMES.get(read.format, read.format)}), values in {read.unit}"
            + (f" (columns in {', '.join(units)})" if read.format == "chart" and len(units) > 1 else "")
            + f"; sex: {sex}",
            f"- made on the `{self.reference.name}` reference set, {self.skin_settings().describe()}; written as "
            f"{', '.join(kind.name for kind in self.formats)}",
            f"- {len(self.made)} row(s): {made} made, {self.count('error')} failed, {self.count('missed')} missed; "
            f"worst difference {self.worst_text()}",
            *(f"- note: {note}" for note in read.notes),
            "",
            f"Each size's measurements in the file's unit ({read.unit}, unless a column says otherwise): what the file "
            "asks (given under its own name, or predicted from the survey, ± the spread left), what the size's "
            "skin measures on its mesh, and the difference.",
            "",
            "| size | measurement | in the file | unit | requested | measured on the skin | difference |",
            "|---|---|---|---|---:|---:|---:|",
        ]
        for made_row in self.made:
            if made_row.result is None:
                continue
            for key, asked, got, off, source, name, sd, _ in self.entries(made_row):
                where = f"`{name}`" if source == "given" else f"predicted (± {sd:.2f})"
                cells = [made_row.row.label, key, where, read.unit_of(key), f"{asked:.2f}", f"{got:.3f}", _signed(off)]
                lines.append("| " + " | ".join(_md(text) for text in cells) + " |")
        unused = {}
        for row in read.rows:
            unused.update(row.unused)
        unknown = sorted({name for row in read.rows for name in row.unknown})
        if unused or unknown:
            lines += ["", "## Not used", ""]
            lines += [f"- `{_md(name)}`: {_md(why)}" for name, why in sorted(unused.items())]
            lines += [f"- `{_md(name)}`: not a name ElliMann knows" for name in unknown]
        warned = [(m.row.label, line) for m in self.made if m.result is not None for line in m.warnings()]
        if warned:
            lines += ["", "## Warnings", ""]
            lines += [f"- {_md(label)}: {_md(line)}" for label, line in warned]
        failed = [m for m in self.made if m.error is not None]
        if failed:
            lines += ["", "## Failed rows", ""]
            lines += [f"- {_md(m.row.label)}: {_md(m.error)}" for m in failed]
        if self.interrupted:
            made, rows = len(self.made), len(read.rows)
            lines += ["", f"Interrupted (Ctrl-C) after {made} of {rows} sizes: the rest were not made."]
        lines += ["", "## Line-up", ""]
        if self.interrupted:
            lines.append("No line-up picture (the run was interrupted).")
        elif self.picture:
            lines.append(f"![The run's skins in size order]({os.path.basename(self.picture)})")
        else:
            lines.append("No line-up picture (it needs Blender, or --no-picture was given).")
        return "\n".join(lines) + "\n"


def _signed(value, digits=3):
    """+0.012, -0.004, 0.000 (no minus on a difference that rounds to zero)."""
    rounded = round(value, digits) + 0.0
    return f"{rounded:.{digits}f}" if rounded == 0 else f"{rounded:+.{digits}f}"


def _md(text):
    """Text for Markdown: control characters escaped (``output.printable``), its pipes too."""
    return printable(str(text)).replace("|", "\\|")
