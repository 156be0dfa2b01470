"""Mirroring across the sagittal plane x = 0: selected ellipsoids, or a whole side of a mannequin.

The mirrored frame gets one axis flipped so it stays right-handed (core.geometry.frames.mirror_frame); the
twin is named with the other suffix (.L <-> .R) and its cushion partner mirrored likewise.
"""

import bpy
from bpy.props import BoolProperty, EnumProperty

from ....core.geometry.frames import mirror_frame
from ....core.mannequin.topology import Part, side_of_name, twin_name
from ... import ids
from ...bridge.convert import (
    SIDE_COLORS,
    ellipsoid_objects,
    new_ellipsoid_object,
    read_part,
    write_frames,
    write_part,
)
from ...bridge.selection import owning_mannequin, part_lookup, selected_ellipsoids
from ..base import ElliMannOperator, MannequinOperator, OperatorError, frames_or_cancel, plural

REPLACE = BoolProperty(
    name="Replace Existing",
    default=False,
    description="Move an existing twin onto the mirror image; otherwise it is left alone",
)


def mirrored_part(part):
    name = twin_name(part.name)
    return Part(
        name, side_of_name(name), part.region, part.girth, part.depends, twin_name(part.partner) if part.partner else ""
    )


def mirror_objects(operator, sources, replace, notes):
    """Mirror each source ellipsoid onto its twin in the same mannequin (created, or replaced if asked)."""
    rotation, center, semi_axes = frames_or_cancel(sources)
    rotation, center = mirror_frame(rotation, center)
    lookups = {}
    created, replaced = [], []
    for i, source in enumerate(sources):
        collection = owning_mannequin(source)
        lookup = lookups.setdefault(collection.name, part_lookup(collection))
        part = mirrored_part(read_part(source))
        twin = lookup.get(part.name)
        if twin is None:
            new_ellipsoid_object(part, rotation[i], center[i], semi_axes[i], collection)
            created.append(part.name)
        elif replace:
            write_part(twin, part)
            twin.color = SIDE_COLORS[part.side]
            write_frames([twin], rotation[i : i + 1], center[i : i + 1], semi_axes[i : i + 1])
            replaced.append(part.name)
        else:
            notes.append(f"'{part.name}' exists in '{collection.name}': left alone (turn on Replace Existing)")
    for note in notes:
        operator.report({"WARNING"}, note)
    if not created and not replaced:
        raise OperatorError("Nothing mirrored: " + (notes[0] if notes else "no left or right ellipsoids"))
    operator.report(
        {"INFO"},
        f"Mirrored {plural(len(created) + len(replaced), 'ellipsoid')}: "
        f"{len(created)} created, {len(replaced)} replaced",
    )
    return {"FINISHED"}


class ELLIMANN_OT_mirror_ellipsoids(ElliMannOperator, bpy.types.Operator):
    """Mirror the selected left/right ellipsoids across x = 0 onto their .L/.R twins"""

    bl_idname = ids.MIRROR_ELLIPSOIDS
    bl_label = "Mirror Selected"
    bl_options = {"REGISTER", "UNDO"}

    replace: REPLACE

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT" and bool(selected_ellipsoids(context))

    def run(self, context):
        selected = selected_ellipsoids(context)
        names = {o.ellimann.part_name for o in selected}
        sources, notes = [], []
        for obj in selected:
            name = obj.ellimann.part_name
            if side_of_name(name) == "C":
                notes.append(f"'{name}' has no .L/.R suffix: it has no twin (use Symmetrize Central)")
            elif twin_name(name) in names:
                notes.append(f"'{name}' and its twin are both selected: select one side only")
            elif owning_mannequin(obj) is None:
                notes.append(f"'{name}' is in no mannequin collection")
            else:
                sources.append(obj)
        if not sources:
            raise OperatorError("Select left (.L) or right (.R) ellipsoids of a mannequin, one side only", notes)
        return mirror_objects(self, sources, self.replace, notes)


class ELLIMANN_OT_mirror_side(MannequinOperator, bpy.types.Operator):
    """Mirror every ellipsoid of one side of the active mannequin across x = 0 onto the other side"""

    bl_idname = ids.MIRROR_SIDE
    bl_label = "Mirror Side"
    bl_options = {"REGISTER", "UNDO"}

    source: EnumProperty(
        name="From",
        default="L",
        description="The side that is copied to the other",
        items=(
            ("L", "Left to Right", "Mirror the .L ellipsoids (+X) onto .R"),
            ("R", "Right to Left", "Mirror the .R ellipsoids (-X) onto .L"),
        ),
    )
    replace: REPLACE

    def run(self, context, collection):
        # The name's suffix, not the side field, decides: it is what the twin's name is made from.
        sources = [o for o in ellipsoid_objects(collection) if side_of_name(o.ellimann.part_name) == self.source]
        if not sources:
            raise OperatorError(f"'{collection.name}' has no .{self.source} ellipsoids to mirror")
        return mirror_objects(self, sources, self.replace, [])


classes = (ELLIMANN_OT_mirror_ellipsoids, ELLIMANN_OT_mirror_side)
