"""ElliMann's data on Blender objects and collections (PropertyGroups), registered as pointers.

``Object.ellimann`` marks an object as a mannequin part (an ellipsoid, or something ElliMann built
from parts: a cushion, a section curve or the skin) and carries the topology fields. ``Collection.ellimann``
marks a collection as a mannequin and keeps its role and measurements.
"""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatVectorProperty, PointerProperty, StringProperty

from ...core.mannequin.skeleton import JOINT_COUNT
from ...core.measurements import MEASUREMENT_LABELS, MEASUREMENTS

SIDE_ITEMS = (
    ("L", "Left", "Left side of the body (+X, Blender's .L)"),
    ("R", "Right", "Right side of the body (-X, Blender's .R)"),
    ("C", "Central", "On the sagittal plane x = 0, symmetric about it"),
)
ROLE_ITEMS = (
    ("base", "Base", "Base Mannequin traced over a reference body"),
    ("reference", "Reference", "Reference Mannequin: known geometry and measurements, used for synthesis"),
    ("synthesized", "Synthesized", "Made by ElliMann from requested measurements"),
)
KIND_ITEMS = (
    ("ELLIPSOID", "Ellipsoid", "A mannequin part: unit-sphere mesh scaled by its semi-axes"),
    ("CUSHION", "Cushion", "Convex hull of a cushion pair, built by ElliMann"),
    ("SECTION", "Section", "A measurement section hull drawn by ElliMann"),
    ("SKIN", "Skin", "The smooth skin over the pieces, built by ElliMann (Build Skin)"),
)
MEASUREMENT_ITEMS = tuple((key, key, MEASUREMENT_LABELS[key]) for key in MEASUREMENTS)


class ELLIMANN_PG_part(bpy.types.PropertyGroup):
    """Topology fields of one ellipsoid (see docs/topology.md)."""

    is_part: BoolProperty(
        name="ElliMann Part", description="This object belongs to an ElliMann mannequin", default=False
    )
    kind: EnumProperty(
        name="Kind",
        items=KIND_ITEMS,
        default="ELLIPSOID",
        description="What this object is: an ellipsoid of the mannequin, or a cushion hull, "
        "section curve or skin ElliMann built from the ellipsoids (rebuilt on demand)",
    )
    part_name: StringProperty(
        name="Part Name",
        description="Topology name in the paper's style, e.g. '10.a Trapezius.L' "
        "(independent of the object's name, which Blender may suffix)",
    )
    side: EnumProperty(
        name="Side",
        items=SIDE_ITEMS,
        default="C",
        description="Side of the body the part is on: left and right parts mirror each other "
        "across x = 0, central parts are symmetric about it",
    )
    region: StringProperty(name="Region", description="Body region, e.g. 'legs'")
    girth: BoolProperty(
        name="Girth Sections",
        default=True,
        description="Takes part in the breast, waist and hip sections (arms and hands do not)",
    )
    depends: EnumProperty(
        name="Depends On",
        items=MEASUREMENT_ITEMS,
        options={"ENUM_FLAG"},
        default={"He"},
        description="Measurements this ellipsoid is interpolated on (segmented IDW)",
    )
    partner: StringProperty(
        name="Cushion Partner", description="Part name of the other ellipsoid of its cushion (empty: none)"
    )
    trace: StringProperty(
        name="Traced From",
        options={"HIDDEN"},
        description="What Fit Ellipsoid fitted this part to: the mesh, its vertices and the fit's "
        "settings (JSON, core.mannequin.traces); Build Reference Set fits the part to the same "
        "vertices on every body",
    )


class ELLIMANN_PG_mannequin(bpy.types.PropertyGroup):
    """A collection that holds one mannequin's ellipsoids."""

    is_mannequin: BoolProperty(
        name="ElliMann Mannequin",
        default=False,
        description="This collection holds an ElliMann mannequin: its ellipsoids, and in "
        "child collections what ElliMann built from them",
    )
    role: EnumProperty(
        name="Role",
        items=ROLE_ITEMS,
        default="synthesized",
        description="What the mannequin is: the traced Base, a Reference used for synthesis, or "
        "one synthesized from measurements",
    )
    has_target: BoolProperty(
        name="Has Target",
        default=False,
        description="Target holds requested measurements (those a mannequin was synthesized "
        "from, or a Reference Mannequin's own)",
    )
    target: FloatVectorProperty(
        name="Target (cm)",
        size=len(MEASUREMENTS),
        min=0.0,
        description="Requested tailor measurements He, Sh, Br, Wa, Hi in cm",
    )
    has_measured: BoolProperty(
        name="Has Measurements",
        default=False,
        description="Measured holds m_T of the mannequin (set by Measure and Synthesize)",
    )
    measured: FloatVectorProperty(
        name="Measured (cm)",
        size=len(MEASUREMENTS),
        min=0.0,
        description="m_T of the mannequin: He, Sh, Br, Wa, Hi in cm",
    )
    # Text, not float properties: Blender's floats are single precision and would move the sections.
    reference_set: StringProperty(
        name="Reference Set",
        description="The reference set the mannequin belongs to or was synthesized from "
        "(empty: female, as in files from before sets had names)",
    )
    section_fractions: StringProperty(
        name="Section Heights",
        description="Where m_T cuts the mannequin, as JSON fractions of He "
        "{Sh, Br, Wa, Hi} (its reference set's; empty: the female ones)",
    )

    has_joints: BoolProperty(
        name="Has Joints",
        default=False,
        description="Joints holds the mannequin's rest joint centres (its skeleton, for posing)",
    )
    joints: FloatVectorProperty(
        name="Joints (m)",
        size=(JOINT_COUNT, 3),
        subtype="NONE",
        description="Rest joint centres in SMPL order (Pelvis, L_Hip, R_Hip, ...), x, y, z each, in metres",
    )


classes = (ELLIMANN_PG_part, ELLIMANN_PG_mannequin)


def register_hooks():
    bpy.types.Object.ellimann = PointerProperty(type=ELLIMANN_PG_part)
    bpy.types.Collection.ellimann = PointerProperty(type=ELLIMANN_PG_mannequin)


def unregister_hooks():
    del bpy.types.Collection.ellimann
    del bpy.types.Object.ellimann
