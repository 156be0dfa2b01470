"""A mannequin's skin in MJCF: MuJoCo's ``<deformable><skin>`` (MuJoCo 3.0 or newer), a mesh that MuJoCo draws
and never collides with, bound to bodies that move it by linear-blend skinning. The pieces stay the geoms that
collide; the skin is what a viewer shows over them.

- In the static MJCF (``core.formats.mjcf``) the skin has one bone, the world: it stands where it was made.
- In the articulated MJCF (``core.formats.mjcf_articulated``) its bones are the 24 SMPL bodies, each bound at its
  rest joint centre with the world's axes (how those bodies stand at rest) and weighted as ``Skin.bones`` gives
  (the weights glTF and Blender's Armature modifier use), so that MuJoCo moves the skin with the body in every
  keyframe and in simulation exactly as ``Skin.posed`` does (``tests/cli/test_cli_skin.py`` compares them).

Coordinates are written to 7 significant digits (MuJoCo keeps them in single precision: about a micrometre).
"""

import xml.etree.ElementTree as ET

import numpy as np

SKIN_RGBA = (0.87, 0.72, 0.62, 1.0)
SKIN_GROUP = 0  # the pieces' geoms are group 1: a viewer hides either by its group
DIGITS = 7


def numbers(values, digits=DIGITS):
    values = np.ravel(values)
    if values.dtype.kind in "iu":
        return " ".join(map(str, values.tolist()))
    return " ".join(f"{v:.{digits}g}" for v in values.tolist())


def add_skin(root, skin, bone_bodies=None, joints=None):
    """Add ``skin`` (a ``core.skin.surface.Skin``) to the MJCF ``root`` under ``<deformable>``: bound to the
    world, or with ``bone_bodies`` (the body name of each SMPL joint) to those bodies at ``joints`` (24, 3), the
    rest joint centres. Returns the skin element."""
    name = f"{skin.mannequin.name or 'mannequin'} skin"
    element = ET.SubElement(
        ET.SubElement(root, "deformable"),
        "skin",
        name=name,
        rgba=numbers(SKIN_RGBA, 4),
        group=str(SKIN_GROUP),
        vertex=numbers(skin.vertices),
        face=numbers(skin.faces.astype(np.int64)),
    )
    if bone_bodies is None:
        ET.SubElement(
            element,
            "bone",
            body="world",
            bindpos="0 0 0",
            bindquat="1 0 0 0",
            vertid=numbers(np.arange(len(skin.vertices))),
            vertweight=numbers(np.ones(len(skin.vertices)), 1),
        )
        return element
    bones, weights = skin.bones()
    for joint, body in enumerate(bone_bodies):
        rows, slots = np.nonzero((bones == joint) & (weights > 0.0))
        if len(rows) == 0:
            continue
        order = np.argsort(rows, kind="stable")
        ET.SubElement(
            element,
            "bone",
            body=body,
            bindpos=numbers(joints[joint]),
            bindquat="1 0 0 0",
            vertid=numbers(rows[order]),
            vertweight=numbers(weights[rows[order], slots[order]]),
        )
    return element


def skin_comment(skin):
    """The MJCF comment's line about the skin."""
    settings = skin.settings
    if settings.kind == "body":
        return f" Skin: the body skin ({len(skin.vertices)} vertices), drawn only: the pieces collide.\n"
    return (
        f" Skin: one closed mesh over the pieces ({len(skin.vertices)} vertices, {settings.voxel_mm:g} mm voxels, "
        f"blend {settings.blend:g}), drawn only: the pieces collide.\n"
    )
