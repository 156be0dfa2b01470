"""The synthesis request of a scene (``Scene.ellimann_synthesis``): its five fields in cm, the extra measurements
ticked, the reference set and options, as the job the core makes (``core.job``)."""

import bpy

from ....core.constants import FEMALE_SET
from ....core.errors import ReferenceSetError
from ....core.job.make import make
from ....core.job.request import Request, check
from ....core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ....core.synthesis.options import SynthesisOptions
from ....core.synthesis.reference_set import cached_reference_set
from ....core.synthesis.shipped import FEMALE_FINE_SET, MALE_FINE_SET, MALE_SET, SHIPPED_SETS

FIELDS = {key: key.lower() for key in MEASUREMENTS}  # He -> props.he
# Each item's number is what a .blend stores: fixed, so that a file saved before the fine sets existed (Folder
# was 2) reopens with the set it chose.
REFERENCE_SET_ITEMS = (
    ("FEMALE", "Female", "The shipped female Reference Mannequins (the paper's Table 2.3)", 0),
    ("MALE", "Male", "The shipped male Reference Mannequins", 1),
    (
        "FEMALE_FINE",
        "Female, fine",
        "The female bodies on the fine topology: more pieces, filling more of each body (docs/topology_fine.md)",
        3,
    ),
    (
        "MALE_FINE",
        "Male, fine",
        "The male bodies on the fine topology: more pieces, filling more of each body (docs/topology_fine.md)",
        4,
    ),
    ("FOLDER", "Folder", "Reference Mannequins of your own, in a folder", 2),
)
_SHIPPED = {"FEMALE": FEMALE_SET, "MALE": MALE_SET, "FEMALE_FINE": FEMALE_FINE_SET, "MALE_FINE": MALE_FINE_SET}


def request_of(props):
    return {key: float(getattr(props, attr)) for key, attr in FIELDS.items()}


def reference_of(props):
    """The ReferenceSet the panel chooses (cached): a shipped set, or the folder in ``props.references``."""
    if props.reference_set != "FOLDER":
        return cached_reference_set(SHIPPED_SETS[_SHIPPED[props.reference_set]])
    if not props.references:
        raise ReferenceSetError("", "References", "is empty: choose the folder of your Reference Mannequins")
    return cached_reference_set(bpy.path.abspath(props.references))


def extra_of(props):
    """The extra measurements the panel gives (ticked), in cm."""
    return {key: float(getattr(props, key)) for key in EXTRA_MEASUREMENTS if getattr(props, f"use_{key}")}


def job_of(props, extra=None, skin=None):
    """The checked job (``core.job.request``) of the panel's request: its five, the extra measurements ticked (or
    ``extra``: a body's, for Synthesize from Mesh), its reference set and options, and a ``skin``
    (``SkinSettings``) if one is asked; ElliMannError naming the field (nothing is made)."""
    request = Request(
        request_of(props),
        reference_of(props),
        extra_of(props) if extra is None else extra,
        options_of(props),
        cushions=props.output == "CUSHIONS",
        skin=skin,
    )
    return check(request)


def synthesize_request(props, extra=None):
    """(Mannequin, measured {the five and the extra ones asked: cm}, warnings) of the panel's request (a live
    step's: no skin); what exact mode missed is one of the warnings."""
    result = make(job_of(props, extra))
    warnings = result.warnings + ([result.missed_text()] if result.missed else [])
    return result.mannequin, result.measured, warnings


def options_of(props):
    """The SynthesisOptions of the panel's fields."""
    return SynthesisOptions(
        mode=props.mode.lower(), metric=props.metric.lower(), power=props.power, normalize=props.normalize.lower()
    )
