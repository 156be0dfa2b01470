"""MJCF (MuJoCo's XML) export of a mannequin: convex pieces as native collision geometry.

Every ellipsoid becomes a native ``ellipsoid`` geom (size = semi-axes) in its own body, whose
pos/quat is the ellipsoid's frame. With ``cushions=True`` each cushion pair becomes one ``mesh``
geom instead, in a body on the first ellipsoid's frame: MuJoCo collides with the convex hull of
a mesh, which is exactly the cushion (:func:`cushion.cushion_mesh`). Bodies have no joints, so
they are welded to the world: a static, collision-only mannequin that loads and simulates as is
(floor plane, timestep and contact defaults included).

Names: bodies and geoms carry the part names verbatim (``"7.a Thigh.L"``); a cushion is named
``"2.a Chest + 2.b Belly"`` (:func:`cushion.cushion_name`). MuJoCo accepts any string as a name and
``xml.etree`` escapes what XML needs, so no sanitising is done; part names are already validated
by the topology (unique, ``number.letter label[.L|.R]``).

With a skin (``--skin``) the file also holds it, drawn and never colliding, bound to the world
(``core.formats.mjcf_skin``).

Measurements go into ``<custom>``: ``numeric`` fields ``target_He`` ... (the requested
measurements, when the mannequin has them) and ``measured_He`` ... (m_T of the ellipsoids), in cm,
plus ``text`` fields ``ellimann_name`` and ``ellimann_role``; a comment at the top repeats them.
"""

import xml.etree.ElementTree as ET

import numpy as np

from ..constants import CUSHION_LEVELS, MJCF_CUSHION_LEVEL
from ..errors import ElliMannError
from ..files import atomic_write_text
from ..geometry.cushion import mannequin_cushions
from ..geometry.mesh import check_subdivision_level
from ..geometry.quaternion import rotation_to_quaternion
from ..measurements import MEASUREMENTS
from .mjcf_skin import add_skin, skin_comment

# Contact and integration defaults for a static mannequin that objects fall onto. MuJoCo's own
# defaults (2 ms steps, 20 ms contact time constant) let a 1 cm ball dropped 0.5 m onto an arm sink
# about 2 cm into it; 1 ms steps with the stiffest safe time constant (2 timesteps) keep it near 1 mm.
# The solref sits in the top-level default so objects a user adds inherit it (MuJoCo mixes the
# solref of the two geoms in contact and clamps it to 2 timesteps if the timestep grows).
TIMESTEP = 0.001  # s
SOLREF = (0.002, 1.0)  # time constant (s), damping ratio
FRICTION = (1.0, 0.005, 0.0001)  # sliding, torsional, rolling
# Cushion hull resolution: level 3 = 642 vertices, volume within about 1% (inscribed) of the exact
# hull and about 38 kB of XML per cushion; level 4 (2,562 vertices) gets 0.25% at four times the size.
SIDE_RGBA = {"L": (0.85, 0.55, 0.45, 1.0), "R": (0.45, 0.6, 0.85, 1.0), "C": (0.8, 0.78, 0.72, 1.0)}
CUSHION_RGBA = (0.72, 0.7, 0.82, 1.0)
MANNEQUIN_CLASS = "ellimann"


def format_numbers(values, digits=9):
    return " ".join(f"{float(v):.{digits}g}" for v in np.ravel(values))


def mannequin_to_mjcf(
    mannequin, cushions=False, subdivisions=MJCF_CUSHION_LEVEL, floor=True, timestep=TIMESTEP, skin=None
):
    """MJCF text for ``mannequin`` (validated first: MannequinError names every problem).

    ``cushions`` replaces each cushion pair by one convex mesh geom built at ``subdivisions``
    (icosphere level of the support directions, 1..6); ``floor`` adds a plane at z = 0; ``skin`` (its
    ``core.skin.surface.Skin``) is drawn over the pieces.
    """
    mannequin.check()
    subdivisions = check_subdivision_level("subdivisions", subdivisions, CUSHION_LEVELS)
    if isinstance(timestep, bool) or not (isinstance(timestep, (int, float)) and 0.0 < timestep <= 0.05):
        raise ElliMannError(f"timestep: must be a number in (0, 0.05] seconds, got {timestep!r}")
    topology = mannequin.topology
    measured = mannequin.measure()

    root = ET.Element("mujoco", model=mannequin.name or "ElliMann mannequin")
    root.append(ET.Comment(summary_comment(mannequin, measured, cushions, skin)))
    ET.SubElement(root, "compiler", angle="radian", autolimits="true")
    # Elliptic friction cones: with MuJoCo's default pyramidal cones, objects resting on the sloped
    # top of an ellipsoid creep and eventually roll off; elliptic cones hold them.
    ET.SubElement(root, "option", timestep=format_numbers([timestep]), integrator="implicitfast", cone="elliptic")

    custom = ET.SubElement(root, "custom")
    ET.SubElement(custom, "text", name="ellimann_name", data=mannequin.name or "unnamed")
    ET.SubElement(custom, "text", name="ellimann_role", data=mannequin.role)
    for prefix, values in (("target", mannequin.measurements), ("measured", measured)):
        for key in [k for k in MEASUREMENTS if k in (values or {})]:
            ET.SubElement(custom, "numeric", name=f"{prefix}_{key}", size="1", data=format_numbers([values[key]]))

    default = ET.SubElement(root, "default")
    ET.SubElement(default, "geom", solref=format_numbers(SOLREF))
    body_class = ET.SubElement(default, "default", {"class": MANNEQUIN_CLASS})
    ET.SubElement(
        body_class, "geom", contype="1", conaffinity="1", condim="3", friction=format_numbers(FRICTION), group="1"
    )

    asset = ET.SubElement(root, "asset")
    for side, rgba in SIDE_RGBA.items():
        ET.SubElement(asset, "material", name=f"ellimann_{side}", rgba=format_numbers(rgba, 4))
    ET.SubElement(asset, "material", name="ellimann_cushion", rgba=format_numbers(CUSHION_RGBA, 4))
    if floor:
        ET.SubElement(
            asset,
            "texture",
            name="grid",
            type="2d",
            builtin="checker",
            width="256",
            height="256",
            rgb1=".85 .85 .85",
            rgb2=".7 .7 .7",
        )
        ET.SubElement(asset, "material", name="floor", texture="grid", texrepeat="8 8", reflectance="0")

    world = ET.SubElement(root, "worldbody")
    ET.SubElement(world, "light", name="sun", directional="true", pos="0 -2 4", dir="0 0.4 -1")
    if floor:
        ET.SubElement(
            world,
            "geom",
            name="floor",
            type="plane",
            size="0 0 0.05",
            material="floor",
            friction=format_numbers(FRICTION),
        )
    holder = ET.SubElement(
        world, "body", name=f"{mannequin.name or 'mannequin'} (ElliMann)", childclass=MANNEQUIN_CLASS
    )

    quats = rotation_to_quaternion(mannequin.rotation)
    for i in topology.single_parts(cushions):
        part = topology.parts[i]
        body = ET.SubElement(
            holder, "body", name=part.name, pos=format_numbers(mannequin.center[i]), quat=format_numbers(quats[i])
        )
        ET.SubElement(
            body,
            "geom",
            name=part.name,
            type="ellipsoid",
            size=format_numbers(mannequin.semi_axes[i]),
            material=f"ellimann_{part.side}",
        )
    for hull in mannequin_cushions(mannequin, subdivisions, local=True) if cushions else []:
        ET.SubElement(
            asset,
            "mesh",
            name=hull.name,
            vertex=format_numbers(hull.vertices, 8),
            face=" ".join(map(str, hull.faces.ravel())),
        )
        body = ET.SubElement(
            holder,
            "body",
            name=hull.name,
            pos=format_numbers(mannequin.center[hull.first]),
            quat=format_numbers(quats[hull.first]),
        )
        ET.SubElement(body, "geom", name=hull.name, type="mesh", mesh=hull.name, material="ellimann_cushion")
    if skin is not None:
        add_skin(root, skin)

    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def write_mjcf(
    mannequin, path, cushions=False, subdivisions=MJCF_CUSHION_LEVEL, floor=True, timestep=TIMESTEP, skin=None
):
    """Write :func:`mannequin_to_mjcf` to ``path`` atomically (nothing is written if it fails)."""
    text = mannequin_to_mjcf(
        mannequin, cushions=cushions, subdivisions=subdivisions, floor=floor, timestep=timestep, skin=skin
    )
    atomic_write_text(path, text)
    return path


def summary_comment(mannequin, measured, cushions, skin=None):
    def row(values):
        return "  ".join(f"{k} {values[k]:.2f}" for k in MEASUREMENTS if k in values)

    lines = [
        f" ElliMann mannequin '{mannequin.name}' (role {mannequin.role}), {len(mannequin)} ellipsoids"
        + (", cushion pairs as convex mesh geoms" if cushions else "")
        + ".",
        " Units: metres; Z up, feet on z = 0, facing -Y. Static: bodies have no joints.",
        f" measured m_T (cm): {row(measured)}",
    ]
    if mannequin.measurements:
        lines.append(f" target (cm):       {row(mannequin.measurements)}")
    if skin is not None:
        lines.append(skin_comment(skin).rstrip("\n"))
    # "--" may not appear inside an XML comment (a mannequin name could hold it).
    return "\n".join(lines).replace("--", "- -") + "\n"
