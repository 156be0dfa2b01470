"""``--skin`` on ``synth``, ``batch`` and ``pose``: its options (generated from ``core.skin.settings.SKIN``, as the
synthesis options are from ``SYNTHESIS``) and the settings they ask for (a job's skin, ``core.job``, which checks
and makes it)."""

from ..core.errors import ElliMannError
from ..core.settings import LEVELS, SKIN
from .arguments import number
from .output import UsageError, one_line

METAVARS = {"skin_voxel": "MM", "skin_blend": "TIMES"}


def flag(name):
    return "--" + name.replace("_", "-")


def add_skin_options(parser, rebuilt=False):
    """--skin, and --skin-kind, --skin-level, --skin-voxel, --skin-blend from the SKIN table (``rebuilt``: the
    command reads a mannequin file, whose skin section, if any, says how its skin was made)."""
    how = (
        "as IN.json's skin section records (the options override it), or, if it records none, as the options say"
        if rebuilt
        else "by --skin-kind (default: the body skin where the set has bodies, the shipped sets have), or over the "
        "pieces at --skin-level (default final), --skin-voxel, --skin-blend"
    )
    parser.add_argument(
        "--skin",
        action="store_true",
        help="make the mannequin's skin, one closed surface (docs/body_skin.md, docs/skin.md), "
        f"{how}: .obj holds the skin alone, .json records how it was made, MJCF draws it over the pieces, "
        ".blend/.glb hold it beside them, bound to the armature; the skin measures the request (the five and "
        "any extra ones asked, within 1 mm on its mesh: the body skin always, the pieces' in exact mode), and its "
        "measurements are reported beside the pieces' m_T",
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
    from ..core.mannequin.skin_record import SkinSettings  # the skin's code, loaded only when a skin is asked

    base = SkinSettings.from_dict(recorded) if recorded else None
    pieces_only = [name for name in ("skin_level", "skin_voxel", "skin_blend") if getattr(args, name) is not None]
    kind = args.skin_kind or (base.kind if base is not None else SKIN["skin_kind"].default)
    if pieces_only and kind == "body":
        raise UsageError(f"{flag(pieces_only[0])} is a setting of the skin over the pieces: the body skin has none")
    if pieces_only and args.skin_kind is None:
        kind = "pieces"  # a voxel, a level or a blend asks for the skin over the pieces
    if args.skin_voxel is not None:
        voxel = args.skin_voxel
    elif args.skin_level is not None:
        voxel = LEVELS[args.skin_level]
    else:
        voxel = base.voxel_mm if base is not None else LEVELS[SKIN["skin_level"].default]
    blend = args.skin_blend if args.skin_blend is not None else (base.blend if base else SKIN["skin_blend"].default)
    try:
        return SkinSettings(voxel, blend, kind)
    except ElliMannError as error:
        raise UsageError(option_named(error)) from None


def option_named(error):
    """A core skin message ("skin_voxel: ...") naming the command line's option instead."""
    text = one_line(error)
    for name in SKIN:
        if text.startswith(f"{name}:"):
            return flag(name) + text[len(name) :]
    return text


def describe(settings):
    """ "body skin", "skin 5 mm" (and its blend when it is not the default): ``SkinSettings.describe``."""
    return settings.describe()
