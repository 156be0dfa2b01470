"""m_T, tailor measuring (paper, Section 2.3.5), of the active mannequin; optionally draws the sections."""

import bpy
from bpy.props import BoolProperty, EnumProperty

from ....core.geometry.cushion import cushion_name
from ....core.measure.extra import mannequin_extra_measurements
from ....core.measure.tailor import as_dict, measure_meshes, section_hulls, tailor_measurements
from ....core.measurements import measurement_line
from ... import ids
from ...bridge.built import built_collection, built_objects, is_stale, new_section_object, remove_built
from ...bridge.convert import ellipsoid_objects, world_triangles, write_measured
from ...bridge.selection import part_lookup
from ..base import MannequinOperator, OperatorError, mannequin_or_cancel

SOURCE_ITEMS = (
    ("AUTO", "Automatic", "On the cushion hulls if cushions are built, else on the ellipsoids"),
    ("ELLIPSOIDS", "Ellipsoids", "On the ellipsoids, in closed form"),
    ("CUSHIONS", "Cushion Hulls", "On the built cushion meshes plus the ellipsoids that are in no cushion"),
)


def cushion_mannequin_meshes(collection, mannequin, cushions):
    """World meshes and girth flags of the cushion mannequin: one hull per pair, the other parts as they are.

    Returns (meshes, girth, names of pairs whose cushion is missing or out of date).
    """
    topology = mannequin.topology
    hull_of = {(c.ellimann.part_name, c.ellimann.partner): c for c in cushions}
    parts = part_lookup(collection)
    meshes, girth, missing, covered = [], [], [], set()
    for i, j in topology.cushion_pairs:
        first, second = topology.parts[i], topology.parts[j]
        obj = hull_of.get((first.name, second.name))
        if obj is None or is_stale(obj, parts):
            missing.append(cushion_name(first.name, second.name))
            continue
        meshes.append(world_triangles(obj))
        girth.append(first.girth or second.girth)
        covered.update((first.name, second.name))
    for obj in ellipsoid_objects(collection):
        if obj.ellimann.part_name not in covered:
            meshes.append(world_triangles(obj))
            girth.append(obj.ellimann.girth)
    return meshes, girth, missing


class ELLIMANN_OT_measure_mannequin(MannequinOperator, bpy.types.Operator):
    """Measure the active mannequin (m_T: He, Sh, Br, Wa, Hi in cm) and store the result on it"""

    bl_idname = ids.MEASURE_MANNEQUIN
    bl_label = "Measure"
    bl_options = {"REGISTER", "UNDO"}

    source: EnumProperty(
        name="Measure On",
        items=SOURCE_ITEMS,
        default="AUTO",
        description="Measure the ellipsoids (exact, closed form) or the cushion mannequin (its hull meshes)",
    )
    draw_sections: BoolProperty(
        name="Draw Sections",
        default=False,
        description="Draw the Sh, Br, Wa and Hi section hulls as curves at their heights "
        "(replacing those drawn before)",
    )

    def run(self, context, collection):
        mannequin = mannequin_or_cancel(collection)
        cushions = built_objects(collection, "CUSHION")
        on_hulls = self.source == "CUSHIONS" or (self.source == "AUTO" and bool(cushions))
        if on_hulls:
            meshes, girth, missing = cushion_mannequin_meshes(collection, mannequin, cushions)
            if missing:
                raise OperatorError(
                    f"Cushions missing or out of date for {', '.join(missing)}: build cushions "
                    "again, or measure on the ellipsoids"
                )
            values, sections = measure_meshes(meshes, girth, mannequin.section_fractions)
        else:
            r, c, d, g = mannequin.rotation, mannequin.center, mannequin.semi_axes, mannequin.topology.girth_mask
            fractions = mannequin.section_fractions  # its reference set's section heights
            values = tailor_measurements(r, c, d, g, fractions)
            sections = section_hulls(r, c, d, g, fractions=fractions) if self.draw_sections else {}
        measured = as_dict(values)
        write_measured(collection, measured)
        if self.draw_sections:
            remove_built(collection, "SECTION")
            target = built_collection(collection, "SECTION")
            for key, (z, points) in sections.items():
                if len(points) >= 3:
                    new_section_object(f"{collection.name} {key}", key, z, points, target)
        where = "cushion hulls" if on_hulls else "ellipsoids"
        more = mannequin_extra_measurements(mannequin)  # closed forms on the ellipsoids, rest pose
        self.report(
            {"INFO"},
            f"'{collection.name}' ({where}): {measurement_line(measured)}, "
            + ", ".join(f"{key} {value:.2f}" for key, value in more.items())
            + " cm (the extra ones "
            "on the ellipsoids)",
        )
        return {"FINISHED"}


classes = (ELLIMANN_OT_measure_mannequin,)
