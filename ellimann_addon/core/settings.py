"""The option tables of the skin, the avatar and the drape: an ``option_table.Option`` per setting (default, label,
descriptions, choices, limits), from which the command line's options and the panels' properties are generated, and
the few numbers they are made of. On the core's ground floor, as ``synthesis.options.SYNTHESIS`` on its package's:
building the command line's parser loads no skin or drape code (their settings' classes,
``core.skin.settings.SkinSettings`` and ``core.drape.settings.DrapeSettings``, read these)."""

from dataclasses import replace

from .constants import COLLIDER_LEVELS
from .option_table import Choice, Option

# The skin's (``core.skin``): its voxel at each level, the range of any voxel, how far neighbours blend.
LEVELS = {"preview": 10.0, "final": 5.0}  # voxel, mm
VOXEL_RANGE_MM = (1.0, 40.0)  # the skin's voxel, mm
BLEND_RANGE = (0.0, 3.0)  # how far neighbours blend, times the thinner piece's smallest semi-axis
DEFAULT_BLEND = 0.6  # times the thinner piece's smallest semi-axis (core.skin.field.blend_widths)

SKIN = {
    "skin_kind": Option(
        "Skin",
        "auto",
        "What the skin is made from: the reference set's own bodies (a body with a face, hands and a navel, corrected "
        "until the tape reads the request) or a smooth surface over the convex pieces",
        "the skin's kind: body (the set's own bodies, corrected until the tape reads the request), pieces (a smooth "
        "surface over the convex pieces, at --skin-level) or auto (default: body where the set has bodies)",
        choices=(
            Choice("auto", "Auto", "The body skin where the reference set has bodies, else the skin over the pieces"),
            Choice("body", "Body", "The reference set's own bodies, interpolated and corrected to the request"),
            Choice("pieces", "Pieces", "A smooth surface over the convex pieces, at the skin level"),
        ),
    ),
    "skin_level": Option(
        "Skin Level",
        "final",
        "How fine the skin is: Preview (10 mm voxels, for live editing) or Final (5 mm, for export and measuring)",
        "the skin's level: preview (10 mm voxels) or final (5 mm, default); --skin-voxel sets any size",
        choices=(
            Choice("preview", "Preview", "10 mm voxels: fast enough to follow the sliders"),
            Choice("final", "Final", "5 mm voxels: for export, measuring and draping"),
        ),
    ),
    "skin_voxel": Option(
        "Voxel",
        None,
        "The skin's voxel in millimetres (overrides the level)",
        "the skin's voxel in mm (default: the level's; {low:g} to {high:g})",
        limits=VOXEL_RANGE_MM,
    ),
    "skin_blend": Option(
        "Blend",
        DEFAULT_BLEND,
        "How far neighbouring pieces blend, in units of the thinner piece's smallest semi-axis (0: a plain union)",
        "how far neighbouring pieces blend, times the thinner one's smallest semi-axis (default {default:g})",
        limits=BLEND_RANGE,
    ),
}

# The avatar's (``core.formats.avatar``: the FBX row's, for garment tools): its rest pose, the bones' names, the
# pieces beside it, the skin's triangle budget.
AVATAR_POSES = ("a_pose", "t_pose")
BONE_NAMINGS = ("smpl", "mixamo")
AVATAR_TRIANGLES = 70_000  # CLO's import guidance for an avatar: at most about 70k triangles
AVATAR_MIN_TRIANGLES = 5_000  # a smaller budget leaves no body to measure

AVATAR = {
    "bones": Option(
        "Bone Names",
        "smpl",
        "The avatar's bone names: SMPL's (L_Hip, ...) or Mixamo's (mixamorig:LeftUpLeg, ...)",
        "an FBX avatar's bone names: smpl (L_Hip, ...; default) or mixamo (mixamorig:LeftUpLeg, ..., as Mixamo's "
        "own files name them)",
        choices=(
            Choice("smpl", "SMPL", "SMPL's joint names"),
            Choice("mixamo", "Mixamo", "Mixamo's bone names, prefixed mixamorig:"),
        ),
    ),
    "proxy": Option(
        "Collision Proxy",
        False,
        "Write the pieces beside the avatar as a collision proxy (each rigid on its bone)",
        "an FBX avatar: write the pieces beside the skin as a collision proxy (each rigid on its bone)",
    ),
    "max_triangles": Option(
        "Triangle Budget",
        AVATAR_TRIANGLES,
        "The most triangles the avatar's skin may have: a finer one is decimated and measured again",
        "an FBX avatar: the most triangles its skin may have (default {default:,}; at least {low:,}): a finer one is "
        "decimated and measured again, and must still meet the request within 2 mm",
        limits=(AVATAR_MIN_TRIANGLES, 10_000_000),
    ),
}

# The drape's (``core.drape``): the garments (their builders: ``core.drape.garments.GARMENTS``), the simulation.
GARMENT_WORDS = {  # kind: (label, description, the command line's words)
    "tube_dress": (
        "Tube Dress",
        "Strapless tube dress, width max(Br, Hi) plus ease, its top edge pinned",
        "strapless, pinned at the top edge",
    ),
    "t_shirt": (
        "T-Shirt",
        "Short-sleeved T-shirt from front, back and sleeve panels, sewn at the shoulders "
        "and armholes (needs arms hanging clear of the torso)",
        "sewn at the shoulders and armholes",
    ),
}
DEFAULT_EDGE = 0.02  # m, target edge length of the cloth mesh (a garment's own default)
EDGE_RANGE = (0.002, 0.2)  # m
FRAME_RANGE = (2, 2000)

DRAPE = {
    "garment": Option(
        "Garment",
        "tube_dress",
        "Garment to cut from the mannequin's measurements and drape on it",
        "{choices}",
        choices=tuple(Choice(kind, *words) for kind, words in GARMENT_WORDS.items()),
    ),
    "frames": Option(
        "Frames",
        60,
        "Frames to simulate (from frame 1, at the scene's frame rate)",
        "frames to simulate (default {default}, at 24 fps)",
        limits=FRAME_RANGE,
    ),
    "edge": Option(
        "Cloth Edge",
        0.025,
        "Edge length of the garment's mesh (smaller: finer folds, slower)",
        "edge length of the cloth mesh in cm (default {default_cm:g}; smaller is finer and slower)",
        limits=EDGE_RANGE,
    ),
    "collider": Option(
        "Collider",
        "pieces",
        "What the cloth collides with: the convex pieces (fastest) or the smooth skin over them (one closed mesh, "
        "no seams for the cloth to catch on)",
        "what the cloth collides with: pieces (the convex pieces, default) or skin (the smooth skin over them, at "
        "--skin-level)",
        choices=(
            Choice("pieces", "Pieces", "The convex pieces: cushions and ellipsoids, or every ellipsoid"),
            Choice("skin", "Skin", "The smooth skin over the pieces, at the skin level"),
        ),
    ),
    "skin_level": replace(
        SKIN["skin_level"],
        default="preview",
        description="How fine the skin collider is: Preview (10 mm voxels, fits as Final does in the drape "
        "benchmark and collides faster) or Final (5 mm)",
        help="the skin collider's level: preview (10 mm voxels, default) or final (5 mm)",
    ),
    "cushions": Option(
        "Cushions",
        True,
        "Collide with the cushions and the ellipsoids not in one (off: every ellipsoid)",
        "collide with the cushions and the ellipsoids not in one; --no-cushions: with every "
        "ellipsoid (default: {default_text})",
    ),
    **{
        f"{what}_subdivisions": Option(
            label,
            2,
            f"Icosphere level of the {pieces} colliders ({COLLIDER_LEVELS[0]}: "
            f"coarsest, {COLLIDER_LEVELS[1]}: finest; triangles = 20 * 4^level)",
            "",
            limits=COLLIDER_LEVELS,
        )
        for what, label, pieces in (
            ("sphere", "Ellipsoid Resolution", "ellipsoid"),
            ("cushion", "Cushion Resolution", "cushion"),
        )
    },
}


def garment_help():
    """``--garment``'s help: each garment's own words, the default marked."""
    option = DRAPE["garment"]
    return " or ".join(
        f"{c.value} ({c.help}{'; default' if c.value == option.default else ''})" for c in option.choices
    )
