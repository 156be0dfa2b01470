"""The tape the correction reads: a body skin measured by the body-mesh measurer's definitions and code
(core.measure.body), the arms known from the bodies' labels, never guessed.

The five (He, Sh, Br, Wa, Hi) are taken with ``measure_body_mesh``'s own steps (its StandingBody sections, its
crossing rule, the same hull), only without the extra measurements' searches: :func:`five` equals
``measure_body_mesh(...).values`` for the five, to the last bit (tests/core/synthesis/test_bodies.py). The correction
reads the six extras with core.body.extra_tape (the measurer's own steps, fast on the fixed topology);
:meth:`full` is the whole measurer (a BodySkin's ``measure()``).
"""

import numpy as np

from ..constants import CM_PER_M, GIRTHS
from ..geometry.mesh import hull_girth, section_segments
from ..measure.body import measure_body_mesh
from ..measurements import EXTRA_MEASUREMENTS, MEASUREMENTS


class Tape:
    """Measures bodies of one topology (``faces``) with arms ``arms`` ({"L", "R": (V,) bool}) at ``fractions``."""

    def __init__(self, faces, arms, fractions):
        self.faces = np.asarray(faces, np.int64)
        self.arms = {side: np.asarray(mask, bool) for side, mask in arms.items()}
        self.fractions = dict(fractions)
        arm_faces = self.arms["L"][self.faces].all(axis=1) | self.arms["R"][self.faces].all(axis=1)
        self.body_rows = np.nonzero(~arm_faces)[0]  # measure_body_mesh's body_rows with arms given

    def five(self, vertices):
        """{He, Sh, Br, Wa, Hi: cm} as measure_body_mesh takes them (with ``arms``)."""
        vertices = np.asarray(vertices, float)
        face_z = vertices[self.faces, 2]
        low, high = face_z.min(axis=1), face_z.max(axis=1)
        bottom = float(vertices[:, 2].min())
        height = float(vertices[:, 2].max()) - bottom
        values = {"He": height}

        def section(z, rows=None):
            if rows is None:
                crossed = np.nonzero((low < z) & (high >= z))[0]
            else:
                crossed = rows[(low[rows] < z) & (high[rows] >= z)]
            return section_segments(vertices, self.faces[crossed], z)[0]

        segments = section(bottom + self.fractions["Sh"] * height)
        values["Sh"] = float(np.ptp(segments[:, :, 0])) if len(segments) else 0.0
        for key in GIRTHS:
            segments = section(bottom + self.fractions[key] * height, self.body_rows)
            values[key] = hull_girth(segments.reshape(-1, 2))[0]
        return {key: float(values[key]) * CM_PER_M for key in MEASUREMENTS}

    def full(self, vertices, neck_tilt=None):
        """measure_body_mesh of ``vertices`` (a BodyMeasurement), the neck square to ``neck_tilt`` (radians; None:
        the tilt a tape settles at)."""
        return measure_body_mesh(vertices, self.faces, self.fractions, neck_tilt=neck_tilt, arms=self.arms)

    def measure(self, vertices, keys, neck_tilt=None):
        """{key: cm} of ``keys``: the five by :meth:`five`, any extra by :meth:`full`."""
        out = self.five(vertices)
        if any(key in EXTRA_MEASUREMENTS for key in keys):
            found = self.full(vertices, neck_tilt).values
            out.update({key: found.get(key, np.nan) for key in EXTRA_MEASUREMENTS if key in keys})
        return {key: out[key] for key in keys}
