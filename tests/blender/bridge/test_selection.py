"""Which mannequin is active: the active object's, else the active collection's."""

import bpy

from devkit.blender_scene import parts, select
from ellimann_addon.blender.bridge.convert import mannequin_to_collection, new_collection
from ellimann_addon.blender.bridge.selection import active_mannequin, set_active_collection


def test_active_mannequin_follows_the_active_object_then_the_active_collection(toy):
    first = mannequin_to_collection(toy, name="First")
    second = mannequin_to_collection(toy, name="Second")
    assert active_mannequin(bpy.context) is None
    set_active_collection(bpy.context, second)
    assert active_mannequin(bpy.context) == second
    select(parts(first)["1.a Head"])
    assert active_mannequin(bpy.context) == first  # the active object wins
    plain = bpy.data.objects.new("Plain", None)
    new_collection("Props").objects.link(plain)
    select(plain)
    assert active_mannequin(bpy.context) == second  # not a mannequin's: back to the active collection
    first.objects.link(plain)
    assert active_mannequin(bpy.context) == first  # any object inside a mannequin collection counts


def test_built_cushions_and_their_collection_lead_to_their_mannequin(toy):
    collection = mannequin_to_collection(toy)
    select(parts(collection)["1.a Head"])
    bpy.ops.ellimann.build_cushions(subdivisions=1)
    cushions = collection.children[0]
    select(cushions.objects[0])
    assert active_mannequin(bpy.context) == collection
    select()
    bpy.context.view_layer.objects.active = None
    set_active_collection(bpy.context, cushions)
    assert active_mannequin(bpy.context) == collection
