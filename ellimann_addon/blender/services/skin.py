"""A mannequin's skin in the scene: made by the core's job (``core.job``, ``core.skin``), written into the
mannequin's built Skin collection (one object, rebuilt in place: ``bridge.skin``), weighted to the SMPL bones (one
vertex group per bone, ``Skin.bones()``) and bound to the mannequin's armature by an Armature modifier when it has
one.

With a skin, the pieces stay beside it as colliders: in a .blend they are hidden (viewport and render) and each gets a
Collision modifier (hidden, not disabled: Blender evaluates them, so cloth collides with them); a .glb keeps them as
nodes (the skin covers them).

Everything the core computes (the surface, the bone weights: ``core.job.make.make(..., bones=True)``) comes before
the scene changes: a SkinError leaves the file as it was.
"""

import bpy
import numpy as np

from ...core.mannequin.skeleton import JOINT_NAMES
from ..bridge.convert import objects_recursive, rig_object
from ..bridge.skin import write_skin_object
from .rig import bind_armature, set_bone_weights

COLLIDER_NAME = "ElliMann Collider"


def add_skin(collection, skin):
    """Write ``skin`` (a core Skin of the mannequin ``collection`` holds) as the collection's skin object (rebuilt in
    place if there is one), its bone groups set when the mannequin has joints and bound to its armature if it has
    one. Returns the object."""
    obj = write_skin_object(collection, skin)
    if skin.mannequin.joints is not None:
        set_bone_weights(obj, skin_bone_weights(skin))
        rig = rig_object(collection)
        if rig is not None:
            bind_armature(obj, rig)
    return obj


def skin_bone_weights(skin):
    """{joint name: (V,) weight} of a core Skin's linear-blend weights (Skin.bones), for an Armature modifier."""
    bones, weights = skin.bones()
    return {
        JOINT_NAMES[joint]: np.where(bones == joint, weights, 0.0).sum(axis=1)
        for joint in np.unique(bones[weights > 0.0])
    }


def pieces_as_colliders(collection, hidden):
    """With a skin the pieces stay as colliders: ``hidden`` (for a .blend) hides every piece in the view layer and in
    renders and gives it a Collision modifier after its armature; False (for a .glb) leaves them as
    ``scene.add_mannequin`` made them. The skin itself is left alone."""
    if not hidden:
        return
    view_layer = bpy.context.view_layer
    view_layer.update()  # new objects get their view-layer bases (hide_set needs them)
    for obj in objects_recursive(collection):
        if not obj.ellimann.is_part or obj.ellimann.kind not in ("ELLIPSOID", "CUSHION") or obj.type != "MESH":
            continue
        obj.hide_render = True
        if view_layer.objects.get(obj.name) == obj:
            obj.hide_set(True, view_layer=view_layer)
        if obj.modifiers.get(COLLIDER_NAME) is None:
            obj.modifiers.new(COLLIDER_NAME, "COLLISION")
