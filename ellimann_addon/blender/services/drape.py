"""Drape a procedural garment on a mannequin with Blender's cloth simulation, headless or in the GUI.

:func:`drape` builds, in a new collection ``"Drape <garment> on <mannequin>"`` under the scene:
- the garment (:mod:`core.drape.garments`, sized from the mannequin's m_T) as a mesh object with a Cloth
  modifier; the garment's ``pins`` form the vertex group "Pin" (the cloth's pin group) and its
  ``seams`` become loose edges pulled together by sewing springs;
- a child collection "Colliders": one object per convex piece (:mod:`core.drape.colliders`: cushions
  and the ellipsoids not in a cushion, or every ellipsoid) with a Collision modifier, hidden in
  the viewport and in renders; or, with the skin as the collider (``DrapeSettings.collider``), one object,
  the mannequin's skin (``core.drape.colliders.skin_collider``), shown: it is the body the cloth lies on.
  The cloth collides with that collection only.
It then steps the frames one by one (``scene.frame_set``, timing each step) and turns the memory
cache into a bake (``ptcache.bake_from_cache``), so a saved .blend replays the drape and opens on
its last frame. The simulated frames are the cloth's point cache range (1..frames), which Blender
simulates whatever the scene's frame range is: the scene's range is left as it was, and past the
cache's end the cloth holds its last frame. The mannequin itself is not touched. Everything that
can fail on bad input is computed before the scene changes; if anything fails once building has
begun, everything the drape made is removed and the scene goes back to its frame (a RuntimeError
of Blender's becomes an ElliMannError; other errors go on as they are).
"""

import contextlib
import time
from dataclasses import dataclass, field

import bpy
import numpy as np
from mathutils import Matrix

from ...core.constants import CLEARING_CUSHION_LEVEL, FIT_CUSHION_LEVEL
from ...core.drape import garments
from ...core.drape.colliders import (
    CollisionPiece,
    collision_pieces,
    skin_collider,
    skin_distance,
    triangle_count,
)
from ...core.drape.fit_metrics import BodyPieces, fit_statistics, mesh_distance
from ...core.drape.settings import MAX_CLOTH_VERTICES, DrapeSettings  # noqa: F401  (DrapeSettings: public here)
from ...core.errors import ElliMannError
from ...core.pose.kinematics import pose_mannequin
from ..bridge.convert import mesh_from_arrays, new_collection
from .drape_motion import PIECE_KEY, animate_drape, show_body
from .rig import check_rig

DRAPE_KEY = "ellimann_drape"  # ID property on a drape collection: the garment's name
PIN_GROUP = "Pin"
CLOTH_NAME = "Cloth"
GARMENT_COLOR = (0.22, 0.45, 0.75, 1.0)
# Distances to a cushion beyond these (m) are only bounded from below, which spares the exact search
# for far points: the fit's distances are exact up to FIT_CUTOFF, the clearing's near the body.
FIT_CUTOFF = 0.2
CLEARING_CUTOFF = 0.05
# Cloth size. Peak memory grows by about 85 kB per garment vertex (measured with both garments on the
# shipped Average RM at 2, 1 and 0.5 cm edges: building, clearing, Blender's cloth and the fit
# together, on top of some 0.3 GB for Blender itself), and time at least as fast: 27,000 vertices (a
# tube dress at 0.5 cm) took 2.6 GB and 2.5 minutes for 3 frames. A drape is refused above
# MAX_CLOTH_VERTICES (about 4 GB, core.synthesis.options) before anything is built; the command line warns above
# WARN_CLOTH_VERTICES.
BYTES_PER_VERTEX = 85_000
WARN_CLOTH_VERTICES = 20_000


@dataclass
class DrapeResult:
    collection: object  # bpy Collection
    garment_object: object  # bpy Object
    garment: garments.Garment
    pieces: list
    seconds: np.ndarray  # wall-clock seconds per simulated frame
    cpu_seconds: np.ndarray  # CPU seconds of this process per simulated frame
    vertices: np.ndarray  # final garment vertices, world (V, 3)
    fit: dict = field(default_factory=dict)  # fit_statistics against the exact pieces (or the skin's mesh)
    body: object = None  # the core mannequin as the cloth last saw it (posed at the last frame of a motion)
    skin: object = None  # the core Skin the cloth collided with (collider "skin"), at rest

    @property
    def frames(self):
        """Frames baked (frame 1, the garment at rest, and the simulated ones)."""
        return len(self.seconds) + 1

    @property
    def seconds_per_frame(self):
        return float(np.mean(self.seconds)) if len(self.seconds) else 0.0

    @property
    def collider_triangles(self):
        return triangle_count(self.pieces)

    def seam_gaps(self):
        """Distance (m) between the two ends of each sewing spring, after the drape."""
        seams = self.garment.seams
        return np.linalg.norm(self.vertices[seams[:, 0]] - self.vertices[seams[:, 1]], axis=1)

    def summary(self):
        fit = self.fit
        collider = "skin" if self.skin is not None else "collider"
        text = (
            f"{self.frames} frames, {self.seconds_per_frame:.3f} s/frame, "
            f"{self.collider_triangles} {collider} triangles; {fit['penetrating']} of {fit['count']} "
            f"vertices inside the body (deepest {fit['max_depth'] * 1e3:.1f} mm), median gap "
            f"{fit['median'] * 1e3:.1f} mm"
        )
        if len(self.garment.seams):
            gaps = self.seam_gaps()
            text += f"; seams closed to {np.median(gaps) * 1e3:.1f} mm (median), {gaps.max() * 1e3:.1f} mm (max)"
        return text


# ------------------------------------------------------------------------------------------------ objects


def garment_object(garment, collection, settings):
    """The garment as a mesh object with a Cloth modifier (pins, sewing springs, collisions limited later)."""
    mesh = mesh_from_arrays(garment.name, garment.vertices, garment.faces)
    seams = np.asarray(garment.seams, dtype=np.int32).reshape(-1, 2)
    if len(seams):
        edges = np.empty(len(mesh.edges) * 2, dtype=np.int32)
        mesh.edges.foreach_get("vertices", edges)
        mesh.edges.add(len(seams))  # loose edges: what Blender's sewing springs pull together
        mesh.edges.foreach_set("vertices", np.concatenate([edges, seams.ravel()]))
        mesh.update()
    mesh.shade_smooth()
    obj = bpy.data.objects.new(garment.name, mesh)
    obj.color = GARMENT_COLOR
    collection.objects.link(obj)
    cloth = obj.modifiers.new(CLOTH_NAME, "CLOTH")
    cloth_settings = cloth.settings
    cloth_settings.quality = settings.quality
    if len(garment.pins):
        group = obj.vertex_groups.new(name=PIN_GROUP)
        group.add([int(i) for i in garment.pins], 1.0, "REPLACE")
        cloth_settings.vertex_group_mass = PIN_GROUP
    if len(seams):
        cloth_settings.use_sewing_springs = True
        cloth_settings.sewing_force_max = settings.sewing_force
    collision = cloth.collision_settings
    collision.distance_min = settings.distance
    collision.collision_quality = settings.collision_quality
    collision.use_self_collision = False  # a single layer of cloth on a convex body: not needed, and slow
    return obj


def collider_objects(pieces, collection):
    """One hidden mesh object with a Collision modifier per piece; ellipsoids share one mesh per resolution."""
    shared = {}
    objects = []
    for piece in pieces:
        key = (piece.kind, len(piece.vertices)) if piece.kind == "ELLIPSOID" else None
        mesh = shared.get(key) if key else None
        if mesh is None:
            mesh = mesh_from_arrays(
                f"Collider {piece.name}" if key is None else f"Collider sphere {len(piece.faces)}",
                piece.vertices,
                piece.faces,
            )
            if key:
                shared[key] = mesh
        obj = bpy.data.objects.new(f"Collider {piece.name}", mesh)
        obj[PIECE_KEY] = piece.name
        obj.matrix_world = Matrix(np.asarray(piece.matrix).tolist())
        obj.display_type = "WIRE"
        obj.hide_render = True
        collection.objects.link(obj)
        obj.modifiers.new("Collision", "COLLISION")
        obj.collision.thickness_outer = 0.001  # the cloth's own distance does the spacing
        objects.append(obj)
    bpy.context.view_layer.update()  # new objects get their view-layer bases (hide_set needs them)
    for obj in objects:
        obj.hide_set(True)  # hidden, not disabled: disabled objects are not evaluated, so they would not collide
    return objects


def setup(garment, pieces, settings, name, parent=None):
    """A new drape collection with the garment and its colliders; returns (collection, garment object,
    collider objects).

    If anything fails on the way, what was built is removed (:func:`removed_on_failure`) before the
    error goes on.
    """
    with removed_on_failure():
        collection = new_collection(name, parent)
        colliders = new_collection("Colliders", collection)
        obj = garment_object(garment, collection, settings)
        obj.modifiers[CLOTH_NAME].collision_settings.collection = colliders
        objects = collider_objects(pieces, colliders)
    return collection, obj, objects


@contextlib.contextmanager
def removed_on_failure():
    """Remove every object, mesh and collection made inside the block if it raises, then re-raise.

    What is made is told from what existed before, so a mesh made before an object used it, or an
    object not yet linked anywhere, goes too (removing the drape collection's contents would miss them).
    """
    kinds = ("objects", "meshes", "collections")  # in removal order: users before what they use
    before = {kind: {block.as_pointer() for block in getattr(bpy.data, kind)} for kind in kinds}
    try:
        yield
    except Exception:
        for kind in kinds:
            data = getattr(bpy.data, kind)
            for block in [b for b in data if b.as_pointer() not in before[kind]]:
                data.remove(block)
        raise


def bake(scene, obj, frames, progress=None):
    """Simulate frames 1..frames frame by frame; returns (wall, cpu): the seconds each of frames
    2..frames took, by the clock and in this process's CPU time (all its threads together).

    ``progress(frame)``, if given, is called once each frame is done. The frames are the cloth's
    point cache range; the scene's frame range is not changed. Leaves the cache baked (saved with
    the .blend) and the scene on the last frame.
    """
    cache = obj.modifiers[CLOTH_NAME].point_cache
    cache.frame_start, cache.frame_end = 1, frames
    scene.frame_set(1)
    if progress is not None:
        progress(1)
    wall, cpu = np.empty(frames - 1), np.empty(frames - 1)
    for frame in range(2, frames + 1):
        start, start_cpu = time.perf_counter(), time.process_time()
        scene.frame_set(frame)
        wall[frame - 2], cpu[frame - 2] = time.perf_counter() - start, time.process_time() - start_cpu
        if progress is not None:
            progress(frame)
    with bpy.context.temp_override(scene=scene, point_cache=cache):
        bpy.ops.ptcache.bake_from_cache()
    return wall, cpu


def evaluated_vertices(obj):
    """World coordinates (V, 3) of an object's evaluated mesh (the cloth at the current frame)."""
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    mesh = evaluated.data
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    matrix = np.array(obj.matrix_world)
    return co.reshape(-1, 3).astype(float) @ matrix[:3, :3].T + matrix[:3, 3]


# ------------------------------------------------------------------------------------------------ size


def cloth_size(mannequin, garment, settings):
    """(vertices, bytes): the cloth's vertex count (estimated from the garment's size and the edge for a
    BUILDERS key, :func:`garments.estimate_vertices`; counted for a Garment) and the memory it needs."""
    if isinstance(garment, str):
        vertices = garments.estimate_vertices(mannequin, garment, settings.edge)
    else:
        vertices = len(garment.vertices)
    return vertices, vertices * BYTES_PER_VERTEX


def check_cloth_size(mannequin, garment, settings):
    """Refuse a cloth of more than ``settings.max_vertices`` vertices, before anything is built: ElliMannError
    with the estimate, the limit and the edge that would fit. Returns (vertices, bytes) otherwise."""
    vertices, size = cloth_size(mannequin, garment, settings)
    limit = settings.max_vertices
    if vertices <= limit:
        return vertices, size
    what = garment if isinstance(garment, str) else garment.name
    text = (
        f"cloth: a {what} with {settings.edge * 100:g} cm edges would have about {vertices:,} vertices and need "
        f"about {_gigabytes(size)} (limit {limit:,} vertices, about {_gigabytes(limit * BYTES_PER_VERTEX)})"
    )
    if isinstance(garment, str):
        fits = _fitting_edge(mannequin, garment, settings.edge, vertices, limit)
        text += (
            f"; an edge of {fits * 100:g} cm or more fits"
            if fits is not None
            else "; no edge up to the largest allowed fits"
        )
    raise ElliMannError(text)


def _fitting_edge(mannequin, kind, edge, vertices, limit):
    """The smallest edge (m, in steps of 0.1 mm) at which the estimate is within ``limit``, or None."""
    step = 1e-4
    trial = np.ceil(edge * np.sqrt(vertices / limit) / step) * step  # vertices go with 1 / edge^2
    while trial <= garments.EDGE_RANGE[1]:
        if garments.estimate_vertices(mannequin, kind, float(trial)) <= limit:
            return round(float(trial), 6)
        trial += step
    return None


def _gigabytes(size):
    return f"{size / 1e9:.1f} GB" if size >= 1e8 else f"{size / 1e6:.0f} MB"


# ------------------------------------------------------------------------------------------------ drape


def drape(
    mannequin, garment="tube_dress", settings=None, name=None, scene=None, progress=None, motion=None, loop=False
):
    """Drape ``garment`` (a ``core.drape.garments.BUILDERS`` key or a core Garment) on ``mannequin`` (a core Mannequin).

    ``motion``: core poses (one, or a motion's frames; ``loop`` for a cycle such as the walk): the body goes
    from rest into them and the cloth follows (``services.drape_motion``); the mannequin needs joints. The
    fit is then measured against the body in the last frame's pose.

    ``settings.collider``: "pieces" (the convex pieces) or "skin" (the mannequin's skin at ``settings.skin_level``,
    one mesh; on a moving body it follows the bones by the skin's own weights).

    A garment named by its key is built from the mannequin's m_T and moved clear of the collider
    (:func:`garments.clear_of`); a Garment given as such is used as it is.

    Returns a :class:`DrapeResult` whose ``fit`` compares the final garment with the exact pieces
    (ellipsoids in closed form, cushions at a fine resolution; distances beyond FIT_CUTOFF, 20 cm, a
    garment hanging far off the body, are lower bounds) or with the skin's mesh: negative distances are
    inside (:func:`fit_distance`). Raises ElliMannError (MannequinError naming the parts, a SkinError, or a
    cloth of more than ``settings.max_vertices`` vertices: :func:`check_cloth_size`) before anything is built.
    ``progress(frame)`` is called as each frame is simulated (see :func:`bake`). Should anything fail once building has
    begun (simulating, or measuring the fit), everything the drape made is removed, the scene goes
    back to its frame and the error goes on; a RuntimeError of Blender's becomes an ElliMannError
    saying what Blender reported.
    """
    settings = (settings or DrapeSettings()).checked()
    scene = scene or bpy.context.scene
    mannequin.check()
    if motion:
        check_rig(mannequin)
    check_cloth_size(mannequin, garment, settings)
    cushions = settings.cushions and bool(mannequin.topology.cushion_pairs)
    skin = None
    if settings.collider == "skin":
        skin, piece = skin_collider(mannequin, settings.skin_level)
        pieces, clearing = [piece], skin_distance(skin)
    else:
        pieces = collision_pieces(mannequin, cushions, settings.sphere_subdivisions, settings.cushion_subdivisions)
        # The builders wrap the ellipsoids, a few mm off; a cushion also fills the hollow between its two.
        clearing_pieces = BodyPieces(mannequin, cushions, CLEARING_CUSHION_LEVEL)
        clearing = lambda points: clearing_pieces.signed_distance(points, CLEARING_CUTOFF)[0]  # noqa: E731
    if isinstance(garment, str):
        garment = garments.clear_of(garments.make_garment(mannequin, garment, edge=settings.edge), clearing)
    name = name or f"Drape {garment.name} on {mannequin.name}"
    frame = scene.frame_current
    stage = "building"
    try:
        with removed_on_failure():
            collection, obj, colliders = setup(garment, pieces, settings, name, scene.collection)
            body, last = mannequin, None
            if motion:
                last = animate_drape(collection, colliders, obj, mannequin, motion, loop, settings.frames, skin)
                body = pose_mannequin(mannequin, last)
            elif skin is not None:
                show_body(colliders)
            stage = "simulating"
            collection[DRAPE_KEY] = garment.name
            wall, cpu = bake(scene, obj, settings.frames, progress)
            vertices = evaluated_vertices(obj)
            fit = fit_statistics(fit_distance(vertices, body, cushions, skin, last))
    except Exception as error:
        if stage == "simulating":
            scene.frame_set(frame)
        if isinstance(error, RuntimeError):
            raise ElliMannError(f"Blender failed while {stage} the drape: {error}") from error
        raise
    return DrapeResult(collection, obj, garment, pieces, wall, cpu, vertices, fit, body, skin)


def fit_distance(points, body, cushions, skin=None, pose=None):
    """Signed distances (P,) of ``points`` to the body the cloth collided with at the end: the exact pieces of
    ``body`` (cushions at a fine resolution; beyond FIT_CUTOFF a lower bound), or the skin's mesh (posed in
    ``pose``, a core Pose, by its own bone weights as the drape's armature moved it; exact)."""
    if skin is None:
        return BodyPieces(body, cushions, FIT_CUSHION_LEVEL).signed_distance(points, FIT_CUTOFF)[0]
    vertices = skin.vertices if pose is None else skin.posed(pose)
    return mesh_distance(points, vertices, skin.faces)[0]


def mesh_piece(name, vertices, faces):
    """A triangle mesh in world coordinates as a collision piece (e.g. a dense body for comparison)."""
    return CollisionPiece(name, "MESH", np.eye(4), np.asarray(vertices, float), np.asarray(faces))
