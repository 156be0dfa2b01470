"""The reference sets the tools build (tools/shipped/build_reference.py the female, tools/shipped/build_male.py the
male) and measure (tools/figures/overlap.py, tools/figures/landmarks.py): which bodies, which reference body, which
targets and which section heights (the landmarks that travel with a set: core.synthesis.reference_set).

Every set is traced with the same selections, made once on the neutral female body: all bodies share one mesh
topology and vertex order (../shared/refmodels_male/README.md), so the same vertices trace the same part on a
male body as on a female one.
"""

import pathlib
from dataclasses import dataclass, replace

from ellimann_addon.core.constants import REFERENCE_MEASUREMENTS, SECTION_FRACTIONS
from ellimann_addon.core.fitting.reference_build import read_targets

REPO = pathlib.Path(__file__).resolve().parents[2]
SHARED = REPO.parent / "shared"
TRACING_FOLDER = SHARED / "refmodels"  # the neutral female body and the region labels the selections use


@dataclass(frozen=True)
class BuildSet:
    name: str
    sex: str
    refmodels: pathlib.Path  # the folder of the six bodies
    reference_body: str  # the neutral body the Base Mannequin is fitted over
    targets: dict  # {stem: {He, Sh, Br, Wa, Hi}} cm, what each Reference Mannequin must measure
    fractions: dict  # section heights (fractions of He) m_T measures at
    out: pathlib.Path  # where the mannequins go
    docs_name: str  # the report the build writes in docs/
    lineup_name: str  # the line-up picture in docs/images/


FEMALE = BuildSet(
    "female",
    "female",
    SHARED / "refmodels",
    "reference_female",
    REFERENCE_MEASUREMENTS,
    SECTION_FRACTIONS,
    REPO / "reference_blends",
    "reference_mannequins.md",
    "reference_lineup.png",
)

# ../shared/refmodels_male: the male targets (its measurements.csv, read as `ellimann references build` reads a
# targets CSV), chosen to span a male population, and the section heights the male bodies were fitted and
# measured with (the natural waist of the neutral male at 0.625 He, the hip cut at 0.515 He, clear of the
# crotch at 0.477).
MALE_TARGETS = read_targets(SHARED / "refmodels_male" / "measurements.csv")
MALE_FRACTIONS = {"Sh": 0.800, "Br": 0.720, "Wa": 0.625, "Hi": 0.515}
MALE = BuildSet(
    "male",
    "male",
    SHARED / "refmodels_male",
    "reference_male",
    MALE_TARGETS,
    MALE_FRACTIONS,
    REPO / "reference_blends" / "male",
    "reference_mannequins_male.md",
    "reference_lineup_male.png",
)

# The same bodies, targets and heights on the fine topology (tools/shipped/reference_topology_fine.py,
# tools/shipped/build_fine.py).
FEMALE_FINE = replace(
    FEMALE,
    name="female-fine",
    out=FEMALE.out / "female-fine",
    docs_name="reference_mannequins_fine.md",
    lineup_name="reference_lineup_fine.png",
)
MALE_FINE = replace(
    MALE,
    name="male-fine",
    out=FEMALE.out / "male-fine",
    docs_name="reference_mannequins_male_fine.md",
    lineup_name="reference_lineup_male_fine.png",
)

BUILD_SETS = {s.name: s for s in (FEMALE, MALE, FEMALE_FINE, MALE_FINE)}
FINE_SETS = {FEMALE.name: FEMALE_FINE, MALE.name: MALE_FINE}  # each set's fine twin
