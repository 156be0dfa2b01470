"""Which mannequin and which ellipsoids an operator or panel works on.

The active mannequin is the mannequin collection of the active object (for a cushion or section
curve, the mannequin it was built for), else the active collection if it is a mannequin (or one
of its built child collections). Every operator and panel goes through :func:`active_mannequin`.
"""

from .built import built_owner
from .convert import ellipsoid_objects, is_ellipsoid, natural_key, new_collection


def owning_mannequin(obj):
    """The mannequin collection ``obj`` belongs to, or None."""
    for collection in obj.users_collection:
        if collection.ellimann.is_mannequin:
            return collection
    for collection in obj.users_collection:
        owner = built_owner(collection)
        if owner is not None:
            return owner
    return None


def active_mannequin(context):
    obj = context.active_object
    if obj is not None:
        found = owning_mannequin(obj)
        if found is not None:
            return found
    collection = context.collection
    if collection is None:
        return None
    return collection if collection.ellimann.is_mannequin else built_owner(collection)


def selected_ellipsoids(context):
    """Selected ellipsoid objects, in part-name order."""
    objects = context.selected_objects or []
    return sorted((o for o in objects if is_ellipsoid(o)), key=lambda o: natural_key(o.ellimann.part_name))


def part_lookup(collection):
    """{part name: object} of a mannequin's ellipsoids."""
    return {o.ellimann.part_name: o for o in ellipsoid_objects(collection)}


def set_active_collection(context, collection):
    """Make ``collection`` the view layer's active collection (so the next new part goes there)."""
    stack = [context.view_layer.layer_collection]
    while stack:
        layer = stack.pop()
        if layer.collection == collection:
            context.view_layer.active_layer_collection = layer
            return
        stack.extend(layer.children)


def new_mannequin_collection(context, name="Mannequin", role="base"):
    """A new, empty mannequin collection under the scene's, made the active collection."""
    collection = new_collection(name, context.scene.collection)
    collection.ellimann.is_mannequin = True
    collection.ellimann.role = role
    set_active_collection(context, collection)
    return collection
