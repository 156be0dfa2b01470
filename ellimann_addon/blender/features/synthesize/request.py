"""The synthesis request of a scene (``Scene.ellimann_synthesis``): its five fields in cm, and the
core synthesis it asks for (segmented IDW over the Reference Mannequins, :func:`core.synthesis.synthesize`)."""

import bpy

from ....core.constants import MEASUREMENTS
from ....core.options import SynthesisOptions
from ....core.synthesis import cached_reference_set, synthesize

FIELDS = {key: key.lower() for key in MEASUREMENTS}  # He -> props.he


def request_of(props):
    return {key: float(getattr(props, attr)) for key, attr in FIELDS.items()}


def synthesize_request(props):
    folder = bpy.path.abspath(props.references) if props.references else None
    reference = cached_reference_set(folder)
    return synthesize(reference, request_of(props), options_of(props))


def options_of(props):
    """The SynthesisOptions of the panel's fields."""
    return SynthesisOptions(mode=props.mode.lower(), metric=props.metric.lower(), power=props.power,
                            normalize=props.normalize.lower())
