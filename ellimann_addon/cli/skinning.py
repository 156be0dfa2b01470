"""``--skin`` on ``synth``, ``batch`` and ``pose``: its options (generated from ``core.skin.settings.SKIN``, as the
synthesis options are from ``SYNTHESIS``), what they turn into, the checks made before any work, and the skin made
for a mannequin: in exact mode its pieces refined until the skin measures the request (``core.skin.exact``), in
IDW the skin of the pieces as they are; the skin's measurements (on its mesh) reported beside the pieces' m_T.

A skin is made per mannequin and dropped once its files are written: a batch's memory stays flat. The skin's core is
imported only when a skin is asked: a command without --skin starts as fast as before."""

import math
from dataclasses import dataclass

from ..core.constants import MEASUREMENTS
from ..core.errors import ElliMannError
from ..core.measure.extra import EXTRA_MEASUREMENTS
from ..core.skin.settings import LEVELS, SKIN, SkinSettings
from .arguments import number
from .output import UsageError, one_line

METAVARS = {"skin_voxel": "MM", "skin_blend": "TIMES"}


def flag(name):
    return "--" + name.replace("_", "-")


def add_skin_options(parser, rebuilt=False):
    """--skin, and --skin-level, --skin-voxel, --skin-blend from the SKIN table (``rebuilt``: the command reads a
    mannequin file, whose skin section, if any, says how its skin was made)."""
    how = (
        "as IN.json's skin section records (--skin-level, --skin-voxel, --skin-blend override it), or at the final "
        "level if it records none"
        if rebuilt
        else "at --skin-level (default final), --skin-voxel, --skin-blend"
    )
    parser.add_argument(
        "--skin",
        action="store_true",
        help="make the mannequin's skin, one closed smooth surface over its pieces (docs/skin.md), "
        f"{how}: .obj holds the skin alone, .json records how it was made, MJCF draws it over the pieces, "
        ".blend/.glb hold it beside them; in exact mode the pieces are refined until the skin measures the "
        "request (He, Sh, Br, Wa, Hi within 1 mm on its mesh), and the skin's measurements are reported beside "
        "the pieces' m_T",
    )
    low, high = SKIN["skin_voxel"].limits
    for name, option in SKIN.items():
        text = option.help.format(default=option.default, low=low, high=high)
        if option.choices:
            parser.add_argument(flag(name), choices=option.values, default=None, help=text)
        else:
            parser.add_argument(flag(name), type=number, default=None, metavar=METAVARS.get(name), help=text)


def skin_settings(args, recorded=None):
    """The SkinSettings of the command line (None without --skin), over a file's ``recorded`` skin section if any:
    an option given wins, then the record, then the table's defaults. UsageError naming the option for a skin
    option without --skin or a value out of its range."""
    given = [name for name in SKIN if getattr(args, name, None) is not None]
    if not args.skin:
        if given:
            raise UsageError(f"{flag(given[0])} is a setting of the skin: add --skin (or drop {flag(given[0])})")
        return None
    base = SkinSettings.from_dict(recorded) if recorded else None
    if args.skin_voxel is not None:
        voxel = args.skin_voxel
    elif args.skin_level is not None:
        voxel = LEVELS[args.skin_level]
    else:
        voxel = base.voxel_mm if base is not None else LEVELS[SKIN["skin_level"].default]
    blend = args.skin_blend if args.skin_blend is not None else (base.blend if base else SKIN["skin_blend"].default)
    try:
        return SkinSettings(voxel, blend)
    except ElliMannError as error:
        raise UsageError(_option_named(error)) from None


def _option_named(error):
    """A core skin message ("skin_voxel: ...") naming the command line's option instead."""
    text = one_line(error)
    for name in SKIN:
        if text.startswith(f"{name}:"):
            return flag(name) + text[len(name) :]
    return text


def describe(settings):
    """ "skin 5 mm" (and its blend when it is not the default)."""
    blend = "" if settings.blend == SKIN["skin_blend"].default else f", blend {settings.blend:g}"
    return f"skin {settings.voxel_mm:g} mm{blend}"


def check_skins_fit(settings, mannequins):
    """Refuse, before any work, a voxel too fine for memory or too coarse for a piece of any of ``mannequins`` (a
    synthesized one, a file's, or a reference set's for a batch): the core's line, naming --skin-voxel."""
    from ..core.skin.surface import SkinError, check_skin  # the skin's core, imported when a skin is asked

    if settings is None:
        return
    for mannequin in mannequins:
        try:
            check_skin(mannequin, settings)
        except SkinError as error:
            raise UsageError(_option_named(error)) from None


@dataclass
class Skinned:
    """What --skin made of a mannequin: the pieces written (``mannequin``: in exact mode refined for the skin),
    their ``skin``, what the skin measures on its mesh (``measured``, cm: the five, and any extra measurement
    asked, by the body-mesh measurer) and the pieces' own m_T (``pieces``); in exact mode the loop's ``rounds``
    and whether the skin met the request (``converged``)."""

    mannequin: object
    skin: object
    measured: dict
    pieces: dict
    exact: bool
    rounds: int = 0
    converged: bool = True

    def misses(self, request):
        """[(key, skin cm, requested cm)] of the measurements asked (the five and any extra ones) further than 1 mm
        on the skin's mesh (exact mode only)."""
        if not self.exact:
            return []
        return [
            (key, self.measured[key], wanted)
            for key, wanted in request.items()
            if abs(self.measured[key] - wanted) > mesh_tolerance_cm()
        ]


def make_skin(mannequin, settings, mode, request, extra=None):
    """The Skinned of ``mannequin`` at ``settings``: in exact ``mode`` its pieces refined until the skin measures
    ``request`` ({He..Hi: cm}) and ``extra`` (the extra measurements asked, {key: cm}), else the skin of the pieces
    as they are, the extra ones measured on it by the body-mesh measurer. SkinError (one line) if the skin cannot be
    made."""
    from ..core.skin.exact import exact_skin
    from ..core.skin.measure import body_measurements, mesh_measurements
    from ..core.skin.surface import build_skin

    if mode == "exact":
        result = exact_skin(mannequin, settings, {key: request[key] for key in MEASUREMENTS}, dict(extra or {}) or None)
        skinned = Skinned(
            result.mannequin,
            result.skin,
            dict(result.skin_measured),
            dict(result.pieces_measured),
            True,
            result.rounds,
            result.converged,
        )
    else:
        skin = build_skin(mannequin, settings)
        skinned = Skinned(mannequin, skin, mesh_measurements(skin), dict(mannequin.measure()), False)
        if extra:
            values = body_measurements(skin).values
            skinned.measured.update({key: values.get(key, math.nan) for key in EXTRA_MEASUREMENTS if key in extra})
    return skinned


def missed_text(missed, rounds):
    """One line for the skin's misses: "exact mode on the skin missed Br by +0.12 cm (skin 101.13 cm for 101.25 cm)
    (tolerance 1 mm on its mesh; ...)"."""
    return (
        "exact mode on the skin missed "
        + ", ".join(f"{key} by {got - want:+z.2f} cm (skin {got:.2f} cm for {want:g} cm)" for key, got, want in missed)
        + f" (tolerance {mesh_tolerance_cm() * 10:g} mm on its mesh; the closest skin found in {rounds} rounds)"
    )


def require_joints_for_skin(mannequin, what):
    """Refuse, before the skin is made, a mannequin without joints asked to pose its skin."""
    if mannequin.joints is None:
        label = f"'{mannequin.name}'" if mannequin.name else "the mannequin"
        raise UsageError(
            f"--pose with --skin: {label} ({what}) has no joints, so neither it nor its skin can be posed: "
            "synthesize it again from a reference set with joints (the shipped sets have them)"
        )


def mesh_tolerance_cm():
    """What exact mode on the skin promises on its mesh (``core.skin.exact.MESH_TOLERANCE_CM``), cm."""
    from ..core.skin.exact import MESH_TOLERANCE_CM

    return MESH_TOLERANCE_CM
