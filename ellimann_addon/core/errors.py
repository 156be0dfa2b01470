"""Errors that name what is wrong, so the Blender layer and the CLI can report them verbatim."""

from dataclasses import dataclass


class ElliMannError(ValueError):
    """Base class: a user-facing problem with input data (never a bug)."""


class FrameError(ElliMannError):
    """A matrix that is not a valid ellipsoid frame (shear, zero or negative scale).

    ``kind`` says which mistake it is, for code that offers a fix: 'matrix' (not an affine 4x4),
    'zero' (a zero scale), 'shear', 'negative' (left-handed) or 'mesh' (transform applied to the mesh).
    """

    def __init__(self, field, message, kind="matrix"):
        self.field = field
        self.kind = kind
        super().__init__(f"{field} {message}")


@dataclass(frozen=True)
class Problem:
    """One validation finding: which ellipsoid (or '' for the mannequin), which field, what."""

    ellipsoid: str
    field: str
    message: str

    def __str__(self):
        # repr, so that a name holding a newline or a quote still gives a one-line message
        where = f"{self.ellipsoid!r} " if self.ellipsoid else ""
        return f"{where}{self.field}: {self.message}"


class MannequinError(ElliMannError):
    """A mannequin or topology that fails validation; ``problems`` lists every finding."""

    def __init__(self, problems):
        self.problems = list(problems)
        head = str(self.problems[0]) if self.problems else "invalid mannequin"
        more = f" (and {len(self.problems) - 1} more)" if len(self.problems) > 1 else ""
        super().__init__(head + more)


class MeasurementError(ElliMannError):
    """A requested measurement that is missing, not a number or outside the plausible range."""

    def __init__(self, field, message):
        self.field = field
        super().__init__(f"{field}: {message}")


class ReferenceSetError(ElliMannError):
    """A reference-mannequin set that cannot be used for synthesis; names the file and the field."""

    def __init__(self, source, field, message):
        self.source = source
        self.field = field
        super().__init__(f"{source}: {field} {message}" if source else f"{field} {message}")


def one_line(error):
    """An error as one line of text (a message's own line breaks and runs of spaces folded; an OSError with its
    file)."""
    if isinstance(error, OSError) and error.filename:
        return f"{error.strerror or error}: {error.filename}"
    return " ".join(str(error).split())
