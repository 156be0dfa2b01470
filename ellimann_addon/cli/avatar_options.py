"""An FBX avatar's options on ``synth`` and ``sizes`` (generated from ``core.settings.AVATAR``): the bones' names,
the pieces beside it as a collision proxy, the skin's triangle budget; its rest pose is the command's ``--pose``
(a_pose or t_pose). What they make: the job's ``core.formats.avatar.AvatarOptions``."""

import os

from ..core.formats.table import format_of
from ..core.settings import AVATAR
from .output import UsageError

FLAGS = {"bones": "--bones", "proxy": "--proxy", "max_triangles": "--max-triangles"}


def add_avatar_options(parser):
    """--bones, --proxy, --max-triangles (each None or False unless given: a command can tell what was asked)."""
    for name, option in AVATAR.items():
        low, _ = option.limits or (None, None)
        text = option.help.format(default=option.default, low=low)
        if option.choices:
            parser.add_argument(FLAGS[name], dest=f"avatar_{name}", choices=option.values, default=None, help=text)
        elif isinstance(option.default, bool):
            parser.add_argument(FLAGS[name], dest=f"avatar_{name}", action="store_true", help=text)
        else:
            parser.add_argument(FLAGS[name], dest=f"avatar_{name}", type=int, metavar="N", default=None, help=text)


def avatar_settings(args, outputs):
    """The AvatarOptions of the command line for ``outputs`` (paths), None when none of them is an
    avatar (.fbx); UsageError (one line) for an avatar option without an avatar to write, or a budget too small."""
    asked = [name for name in AVATAR if getattr(args, f"avatar_{name}") not in (None, False)]
    avatars = [path for path in outputs if _is_avatar(path)]
    if not avatars:
        if asked:
            raise UsageError(f"{FLAGS[asked[0]]} is an option of an FBX avatar: write a .fbx (or drop it)")
        return None
    from ..core.formats.avatar import AvatarOptions  # the avatar's code, loaded only when one is written

    budget = args.avatar_max_triangles
    low = AVATAR["max_triangles"].limits[0]
    if budget is not None and budget < low:
        raise UsageError(f"--max-triangles must be at least {low:,} (a smaller budget leaves no body to measure)")
    return AvatarOptions(
        naming=args.avatar_bones or AVATAR["bones"].default,
        proxy=bool(args.avatar_proxy),
        max_triangles=AVATAR["max_triangles"].default if budget is None else budget,
    )


def _is_avatar(path):
    kind = format_of(os.fspath(path))
    return kind is not None and kind.needs_skin
