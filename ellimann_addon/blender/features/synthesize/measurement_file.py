"""Open Measurement File: a measurement file people have (a Seamly2D / Valentina .vit or .vst, a FreeSewing set, a
size chart: ``core.sizing``) as a preset of the Synthesize panel. One person or size (a chart's or a table's first,
or the one named) fills the five and the extra measurements' fields (ticking the ones given, unticking the others)
and, for a file of a man or a woman, the shipped set of that sex; the status bar says which values were used,
predicted (with the spread left) and not used. A file or a size that cannot be used changes nothing and says why in
one line. One undo step, and with Live on one live update (as a preset)."""

import os

import bpy
from bpy.props import StringProperty

from ....core.errors import ElliMannError, one_line
from ....core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ... import ids
from ..base import ElliMannOperator, OperatorError
from .live import hold_live_updates, release_live_updates
from .request import FIELDS

FILTER = "*.vit;*.vst;*.json;*.csv"
SEX_SETS = {  # the panel's shipped set -> the same kind of set of the file's sex
    "female": {"MALE": "FEMALE", "MALE_FINE": "FEMALE_FINE"},
    "male": {"FEMALE": "MALE", "FEMALE_FINE": "MALE_FINE"},
}


def chosen_row(read, size):
    """The row of ``read`` (a MeasurementFile) labelled ``size`` (any case; empty: the first); OperatorError (one
    line) when the file has no such size or the row failed."""
    rows = read.rows
    if not rows:
        raise OperatorError(f"{os.path.basename(read.path)}: holds no person or size")
    if size.strip():
        found = [row for row in rows if row.label.casefold() == size.strip().casefold()]
        if not found:
            labels = ", ".join(row.label for row in rows[:12]) + (", ..." if len(rows) > 12 else "")
            raise OperatorError(f"{os.path.basename(read.path)}: no size {size.strip()!r}; it has {labels}")
        rows = found
    if not rows[0].ok:
        raise OperatorError(rows[0].error)
    return rows[0]


def status_line(read, row):
    """ "Jane Doe (jane.vit): used He, Br, ...; predicted Sh 43.34 cm (± 1.13); not used: a, b; unknown: c"."""
    used = [key for key in (*MEASUREMENTS, *EXTRA_MEASUREMENTS) if key in row.values and key not in row.predicted]
    parts = [f"{row.label} ({os.path.basename(read.path)}): used {', '.join(used) or 'none'}"]
    if row.predicted:
        parts.append(
            "predicted " + ", ".join(f"{key} {value:.2f} cm (± {sd:.2f})" for key, (value, sd) in row.predicted.items())
        )
    if row.unused:
        parts.append("not used: " + ", ".join(row.unused))
    if row.unknown:
        parts.append("unknown: " + ", ".join(row.unknown))
    return "; ".join(parts)


class ELLIMANN_OT_open_measurement_file(ElliMannOperator, bpy.types.Operator):
    """Fill the measurements from a .vit, .vst, FreeSewing set or size chart; a missing one of the five is predicted"""

    bl_idname = ids.OPEN_MEASUREMENT_FILE
    bl_label = "Open Measurement File"
    bl_options = {"REGISTER", "UNDO"}

    filepath: StringProperty(name="File", subtype="FILE_PATH", description="The measurement file to read")
    filter_glob: StringProperty(default=FILTER, options={"HIDDEN"})
    size: StringProperty(
        name="Size",
        default="",
        description="The size to use, by its label (a chart's first column, a multisize table's size or alias); "
        "empty: the first",
    )

    @classmethod
    def poll(cls, context):
        return context.scene is not None and hasattr(context.scene, "ellimann_synthesis")

    def invoke(self, context, _event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def run(self, context):
        from ....core.sizing.readers import read_measurement_file  # the readers, loaded when a file is opened

        props = context.scene.ellimann_synthesis
        path = bpy.path.abspath(self.filepath)
        try:  # everything read and checked before any field changes
            read = read_measurement_file(path, extrapolate=True)  # out of the set's range: a warning, as a field
        except (ElliMannError, OSError) as error:
            raise OperatorError(one_line(error)) from None
        row = chosen_row(read, self.size)
        reference_set = SEX_SETS.get(read.sex, {}).get(props.reference_set, props.reference_set)
        hold_live_updates()  # one live update for every field set
        try:
            for key, attr in FIELDS.items():
                setattr(props, attr, row.values[key])
            extra = row.extra()
            for key in EXTRA_MEASUREMENTS:
                setattr(props, f"use_{key}", key in extra)
                if key in extra:
                    setattr(props, key, extra[key])
            if reference_set != props.reference_set:
                props.reference_set = reference_set
        finally:
            release_live_updates(context.scene)
        for line in [*read.notes, *row.warnings]:
            self.report({"WARNING"}, line)
        self.report({"INFO"}, status_line(read, row))
        return {"FINISHED"}


classes = (ELLIMANN_OT_open_measurement_file,)
