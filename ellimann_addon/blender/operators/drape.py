"""Drape: a garment sized from the active mannequin, simulated with Blender cloth on its convex pieces."""

import bpy

from ...core.errors import ElliMannError, MannequinError
from .. import ids
from ..convert import collection_to_mannequin
from ..drape import drape
from ..selection import active_mannequin
from .common import cancel

PENETRATION_WARNING = 0.01  # fraction of garment vertices inside the body worth a warning


class ELLIMANN_OT_drape_garment(bpy.types.Operator):
    """Drape a garment sized from the active mannequin's measurements, with its convex pieces as cloth colliders"""

    bl_idname = ids.DRAPE_GARMENT
    bl_label = "Drape Garment"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return (context.mode == "OBJECT" and hasattr(context.scene, "ellimann_drape")
                and active_mannequin(context) is not None)

    def execute(self, context):
        collection = active_mannequin(context)
        props = context.scene.ellimann_drape
        try:
            mannequin = collection_to_mannequin(collection)
        except MannequinError as error:
            return cancel(self, f"Fix '{collection.name}' first", error.problems)
        try:
            result = drape(mannequin, props.garment, props.settings(), scene=context.scene)
        except MannequinError as error:
            return cancel(self, f"Cannot drape '{collection.name}'", error.problems)
        except ElliMannError as error:
            return cancel(self, f"Cannot drape '{collection.name}': {error}")
        props.status = result.summary()
        if result.fit["penetrating_fraction"] > PENETRATION_WARNING:
            self.report({"WARNING"}, f"{result.fit['penetrating']} garment vertices ended inside the body: try more "
                                     "frames, a finer collider or a finer cloth")
        self.report({"INFO"}, f"Draped a {result.garment.name} on '{collection.name}' in "
                              f"'{result.collection.name}': {props.status}")
        return {"FINISHED"}


classes = (ELLIMANN_OT_drape_garment,)
register, unregister = bpy.utils.register_classes_factory(classes)
