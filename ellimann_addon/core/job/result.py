"""What one job made, as data: the mannequin (its pieces), what they measure, its skin and what the skin measures,
its poses, what exact mode missed, and the lines to tell the user. Callers write the files and word their reports
from it."""

import math
from dataclasses import dataclass, field

from ..measurements import MEASUREMENTS
from ..synthesis.misses import SKIN_MISS_CM, missed_text, skin_missed_text
from ..synthesis.refine import EXACT_TOLERANCE


@dataclass
class SkinMade:
    """A mannequin's skin as the job made it: the ``skin`` (``core.skin.surface.Skin``), what it measures on its
    mesh (``measured``, {key: cm}: the five and the extra measurements asked), whether exact mode made it measure the
    request (``exact``), the rounds that took and whether it got there (``converged``)."""

    skin: object
    measured: dict
    exact: bool
    rounds: int = 0
    converged: bool = True

    @property
    def settings(self):
        return self.skin.settings


@dataclass
class Result:
    """One job's outcome. ``mannequin``: the pieces (in exact mode with a skin, refined for it); ``measured``: their
    m_T and the extra measurements asked ({key: cm}); ``request``: the five and the extra ones asked ({key: cm};
    None for a mannequin already made); ``skin``: a :class:`SkinMade` or None; ``frames``: the poses (a list of
    ``core.pose.kinematics.Pose``; None without a pose) at ``fps``; ``missed``: what exact mode missed
    (``core.synthesis.misses.Miss``: the pieces' request, or with a skin the skin's; worded by :meth:`missed_text`);
    ``warnings``: the request's (outside the reference range), extra measurements IDW does not meet, joints a clip
    was clamped at; ``notes``: where a clip's feet went."""

    mannequin: object
    measured: dict
    request: dict = None
    mode: str = "exact"
    skin: SkinMade | None = None
    frames: list | None = None
    fps: float | None = None
    missed: list = field(default_factory=list)
    warnings: list = field(default_factory=list)
    notes: list = field(default_factory=list)

    @property
    def five(self):
        """The pieces' m_T {He..Hi: cm}."""
        return {key: self.measured[key] for key in MEASUREMENTS}

    def shown(self):
        """What a user is shown as measured: the skin's measurements with a skin, else the pieces'."""
        return self.skin.measured if self.skin is not None else self.measured

    def avatar_request(self):
        """{key: cm} an avatar of this result's skin must still measure once decimated (``core.formats.avatar``):
        the request where the skin meets it (exact mode on the skin, within its tolerance), else what the skin
        itself measures (a skin of IDW's pieces, a measurement exact mode missed); None without a skin or a
        request."""
        if self.skin is None or self.request is None:
            return None
        found = {}
        for key, asked in self.request.items():
            got = self.skin.measured.get(key)
            if got is None or not math.isfinite(got):
                continue
            found[key] = asked if self.skin.exact and abs(got - asked) <= SKIN_MISS_CM else float(got)
        return found

    def missed_text(self):
        """One line for what was missed ("" if nothing), the pieces' or the skin's."""
        if not self.missed:
            return ""
        return missed_text(self.missed) if self.skin is None else skin_missed_text(self.missed, self.skin.rounds)


def tolerance_text(skinned):
    """What exact mode promises, for a line that counts misses: "0.001%" (the pieces) or "1 mm on the skin"."""
    return f"{SKIN_MISS_CM * 10:g} mm on the skin" if skinned else f"{EXACT_TOLERANCE * 100:g}%"
