"""The one table behind each job's options: an :class:`Option` (default, label, descriptions, choices, limits)
per setting, from which the command line's argparse options and the panels' property items are generated, so
they cannot disagree. The tables themselves live with their jobs (``synthesis.options.SYNTHESIS``,
``drape.settings.DRAPE``)."""

from dataclasses import dataclass


@dataclass(frozen=True)
class Choice:
    value: str  # what the core and the command line take ("exact"); the panel's item is value.upper()
    label: str  # the panel's item label
    description: str  # the panel's item tooltip
    help: str = ""  # the command line's wording, where it has its own


@dataclass(frozen=True)
class Option:
    label: str  # the panel's property name
    default: object
    description: str  # the panel's tooltip
    help: str  # the command line's --help ({default} is filled in)
    choices: tuple = ()  # Choice, in the core's order
    shown: tuple = ()  # the panel's order of the choices' values (default: the core's)
    limits: tuple = ()  # (low, high) of a number

    @property
    def values(self):
        return tuple(choice.value for choice in self.choices)

    def enum_items(self):
        """EnumProperty items: (VALUE, label, description) in the panel's order."""
        by_value = {choice.value: choice for choice in self.choices}
        return tuple(
            (value.upper(), by_value[value].label, by_value[value].description) for value in (self.shown or self.values)
        )

    @property
    def enum_default(self):
        return self.default.upper()
