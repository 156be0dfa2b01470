"""A mannequin's skin in the scene: made by the core (``core.skin``), written into the mannequin's built Skin
collection (one object, rebuilt in place: ``bridge.skin``), weighted to the SMPL bones (one vertex group per bone,
``Skin.bones()``) and bound to the mannequin's armature by an Armature modifier when it has one.

With a skin, the pieces stay beside it as colliders: in a .blend they are hidden (viewport and render) and each gets a
Collision modifier (hidden, not disabled: Blender evaluates them, so cloth collides with them); a .glb keeps them as
nodes (the skin covers them).

Everything the core computes (the surface, the bone weights) comes before the scene changes: a SkinError leaves the
file as it was.
"""

import bpy
import numpy as np

from ...core.mannequin.skeleton import JOINT_NAMES
from ...core.skin.exact import exact_skin
from ...core.skin.surface import build_skin
from ..bridge.convert import objects_recursive, rig_object
from ..bridge.skin import write_skin_object
from .rig import bind_armature, set_bone_weights

COLLIDER_NAME = "ElliMann Collider"


def make_skin(mannequin, settings, progress=None):
    """The core Skin of ``mannequin`` at ``settings``, with its bone weights made when it has joints (the slow parts,
    before any scene change). ``progress(fraction, message)``: called as the parts finish. SkinError (one line)."""
    report = progress or (lambda fraction, message: None)
    report(0.0, f"making the skin ({settings.voxel_mm:g} mm voxels)")
    skin = build_skin(mannequin, settings)
    if mannequin.joints is not None:
        report(0.7, "weighting it to the bones")
        skin.bones()
    report(0.9, "writing it")
    return skin


def make_exact_skin(mannequin, settings, request, extra=None, progress=None):
    """Exact mode on the skin (``core.skin.exact.exact_skin``): pieces near ``mannequin`` whose skin at ``settings``
    measures ``request`` ({He..Hi: cm}) and ``extra``, the skin weighted to the bones when it has joints (before any
    scene change). Returns the ExactSkin; ``progress`` as :func:`make_skin`'s."""
    report = progress or (lambda fraction, message: None)
    report(0.0, f"refining the pieces until their skin measures the request ({settings.voxel_mm:g} mm voxels)")
    result = exact_skin(mannequin, settings, request, extra or None)
    if result.mannequin.joints is not None:
        report(0.8, "weighting it to the bones")
        result.skin.bones()
    report(0.9, "writing it")
    return result


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
