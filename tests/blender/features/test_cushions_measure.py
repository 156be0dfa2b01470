"""Building cushions, and m_T on objects: on ellipsoids, on cushion hulls, with section curves."""

import bpy
import numpy as np
import pytest

from devkit.blender_scene import parts, select, state
from ellimann_addon.blender.bridge.built import BUILT_KEY, built_objects
from ellimann_addon.blender.bridge.convert import mannequin_to_collection, world_triangles
from ellimann_addon.core.geometry import mesh
from ellimann_addon.core.geometry.cushion import cushion_mesh
from ellimann_addon.core.geometry.ellipsoid import volume
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.topology import Part, Topology
from ellimann_addon.core.measure.tailor import measure_meshes, section_heights
from ellimann_addon.core.measurements import MEASUREMENTS


def capsule_mannequin(radius=0.1, length=0.5):
    """Two equal spheres one above the other: their cushion is a capsule (closed-form volume)."""
    topology = Topology(
        [
            Part("1.a Upper", "C", "torso", True, ("He",), "1.b Lower"),
            Part("1.b Lower", "C", "torso", True, ("He",), "1.a Upper"),
        ]
    )
    center = np.array([(0.0, 0.0, radius + length), (0.0, 0.0, radius)])
    return Mannequin(topology, np.stack([np.eye(3)] * 2), center, np.full((2, 3), radius), name="Capsule")


def cushions(collection):
    return sorted(built_objects(collection, "CUSHION"), key=lambda o: o.name)


def test_cushion_is_a_closed_convex_mesh_of_the_capsule_volume():
    r, length = 0.1, 0.5
    collection = mannequin_to_collection(capsule_mannequin(r, length))
    select(parts(collection)["1.a Upper"])
    assert bpy.ops.ellimann.build_cushions() == {"FINISHED"}
    (obj,) = cushions(collection)
    assert obj.name == "1.a Upper + 1.b Lower" and obj.ellimann.partner == "1.b Lower"
    assert obj.users_collection[0].name == "Capsule Cushions" and obj.users_collection[0][BUILT_KEY] == "CUSHION"
    vertices, faces = world_triangles(obj)
    assert mesh.is_closed_manifold(faces) and mesh.euler_characteristic(vertices, faces) == 2
    assert mesh.convexity_defect(vertices, faces) < 1e-6
    exact = np.pi * r * r * length + 4.0 / 3.0 * np.pi * r**3
    assert mesh.volume(vertices, faces) == pytest.approx(exact, rel=5e-3)
    # The object sits in the first ellipsoid's rigid frame, its vertices are local to it.
    assert np.allclose(np.array(obj.matrix_world), [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, r + length], [0, 0, 0, 1]])


def test_toy_cushions_match_the_core_hulls(toy, toy_collection):
    assert bpy.ops.ellimann.build_cushions(subdivisions=3) == {"FINISHED"}
    built = {o.ellimann.part_name: o for o in cushions(toy_collection)}
    assert sorted(built) == ["2.a Chest", "6.a Thigh.L", "6.a Thigh.R"]
    for i, j in toy.topology.cushion_pairs:
        first, second = ((toy.rotation[k], toy.center[k], toy.semi_axes[k]) for k in (i, j))
        core_vertices, core_faces = cushion_mesh(first, second, 3)
        vertices, faces = world_triangles(built[toy.topology.names[i]])
        assert mesh.is_closed_manifold(faces) and mesh.convexity_defect(vertices, faces) < 1e-6
        expected = mesh.volume(core_vertices, core_faces)
        assert mesh.volume(vertices, faces) == pytest.approx(expected, rel=1e-5)
        assert expected > max(volume(toy.semi_axes[i]), volume(toy.semi_axes[j]))


def test_rebuilding_replaces_only_what_was_built(toy_collection):
    bpy.ops.ellimann.build_cushions(subdivisions=2)
    folder = toy_collection.children[0]
    mine = bpy.data.objects.new("My note", None)
    folder.objects.link(mine)
    first = {o.name for o in cushions(toy_collection)}
    meshes = len(bpy.data.meshes)
    assert bpy.ops.ellimann.build_cushions(subdivisions=2) == {"FINISHED"}
    assert {o.name for o in cushions(toy_collection)} == first  # same names: the old ones are gone
    assert len(bpy.data.meshes) == meshes and "My note" in folder.objects
    assert len(toy_collection.children) == 1


def test_build_cushions_refuses_mannequins_without_pairs_or_with_bad_frames(toy):
    plain = toy.copy()
    plain.topology = Topology([Part(p.name, p.side, p.region, p.girth, p.depends) for p in toy.topology])
    collection = mannequin_to_collection(plain)
    select(parts(collection)["1.a Head"])
    before = state()
    with pytest.raises(RuntimeError, match="has no cushion pairs"):
        bpy.ops.ellimann.build_cushions()
    assert state() == before
    broken = mannequin_to_collection(toy, name="Broken")
    parts(broken)["2.b Belly"].scale.y *= -1
    bpy.context.view_layer.update()
    select(parts(broken)["1.a Head"])
    before = state()
    with pytest.raises(RuntimeError, match="Fix 'Broken' first"):
        bpy.ops.ellimann.build_cushions()
    assert state() == before


def test_measure_on_objects_agrees_with_the_core(toy, toy_collection):
    assert bpy.ops.ellimann.measure_mannequin() == {"FINISHED"}
    props = toy_collection.ellimann
    expected = toy.measure()
    assert props.has_measured
    assert list(props.measured) == pytest.approx([expected[m] for m in MEASUREMENTS], rel=1e-5)


def test_measure_draws_section_curves_and_replaces_them(toy, toy_collection):
    assert bpy.ops.ellimann.measure_mannequin(draw_sections=True) == {"FINISHED"}
    sections = built_objects(toy_collection, "SECTION")
    assert sorted(o.ellimann.part_name for o in sections) == ["Br", "Hi", "Sh", "Wa"]
    _, _, z = section_heights(toy.rotation, toy.center, toy.semi_axes)
    for obj in sections:
        points = np.array([p.co for p in obj.data.splines[0].points])
        assert np.allclose(points[:, 2], z[obj.ellimann.part_name], atol=1e-6)
        assert obj.data.splines[0].use_cyclic_u
    assert bpy.ops.ellimann.measure_mannequin(draw_sections=True) == {"FINISHED"}
    assert len(built_objects(toy_collection, "SECTION")) == 4 and len(bpy.data.curves) == 4


def test_cushion_mannequin_is_measured_on_its_hull_meshes(toy, toy_collection):
    bpy.ops.ellimann.build_cushions(subdivisions=3)
    assert bpy.ops.ellimann.measure_mannequin(source="AUTO") == {"FINISHED"}
    got = np.array(toy_collection.ellimann.measured)
    # The same cushion mannequin assembled in the core: hulls of the pairs, the unit sphere for the rest.
    unit, faces = mesh.icosphere(3)
    meshes, girth, paired = [], [], set()
    for i, j in toy.topology.cushion_pairs:
        first, second = ((toy.rotation[k], toy.center[k], toy.semi_axes[k]) for k in (i, j))
        meshes.append(cushion_mesh(first, second, 3))
        girth.append(toy.topology.parts[i].girth or toy.topology.parts[j].girth)
        paired.update((i, j))
    for k in sorted(set(range(len(toy))) - paired):
        meshes.append(((unit * toy.semi_axes[k]) @ toy.rotation[k].T + toy.center[k], faces))
        girth.append(toy.topology.parts[k].girth)
    expected, _ = measure_meshes(meshes, girth)
    assert got == pytest.approx(expected, rel=1e-5)
    ellipsoids = np.array([toy.measure()[m] for m in MEASUREMENTS])
    assert got[2:] != pytest.approx(ellipsoids[2:], rel=1e-3)  # the hulls really are measured
    assert bpy.ops.ellimann.measure_mannequin(source="ELLIPSOIDS") == {"FINISHED"}
    assert np.array(toy_collection.ellimann.measured) == pytest.approx(ellipsoids, rel=1e-5)


def test_measure_refuses_out_of_date_or_missing_cushions(toy_collection):
    before = state()
    with pytest.raises(RuntimeError, match="Cushions missing or out of date"):
        bpy.ops.ellimann.measure_mannequin(source="CUSHIONS")
    assert state() == before
    bpy.ops.ellimann.build_cushions(subdivisions=2)
    parts(toy_collection)["6.b Shin.L"].location.z += 0.01
    bpy.context.view_layer.update()
    before = state()
    with pytest.raises(RuntimeError, match=r"out of date for 6.a Thigh.L \+ 6.b Shin.L"):
        bpy.ops.ellimann.measure_mannequin()
    assert state() == before
    # Moving the whole mannequin (registration) keeps them up to date.
    bpy.ops.ellimann.build_cushions(subdivisions=2)
    bpy.ops.ellimann.register_mannequin()
    assert bpy.ops.ellimann.measure_mannequin() == {"FINISHED"}


def test_measure_refuses_an_invalid_mannequin_and_needs_one(toy_collection):
    parts(toy_collection)["5.a Arm.R"].ellimann.part_name = "5.a Arm.X"
    before = state()
    with pytest.raises(RuntimeError, match="Fix 'toy' first"):
        bpy.ops.ellimann.measure_mannequin()
    assert state() == before
    bpy.ops.wm.read_homefile(use_empty=True)
    assert not bpy.ops.ellimann.measure_mannequin.poll()
