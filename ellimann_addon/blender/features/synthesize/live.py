"""Live updates of the Synthesize feature: the last synthesized mannequin follows the request in place.

A live step synthesizes the request (the extra measurements only when one is given: the panel shows the five)
and moves what is there. Cushions keep up with a dragged slider by moving the existing cushion meshes: their
vertices are rewritten in place (``core.geometry.cushion.cushion_vertices``, every pair in one vectorised call;
same vertex order at the same resolution) and their faces kept; a cushion the armature cut in two at a joint
(``services.rig``) keeps its halves, whose vertices follow the hull's (``core.pose.posed_pieces.clipped_vertices``).
Those faces were made convex for the previous ellipsoids, so the cushions count as out of date until the fields
have been still for ``LIVE_SETTLE_SECONDS``; a timer then rebuilds them exactly (``settle_live``), and cuts them
again. What follows the pieces (a preview skin) hooks in at :func:`pieces_moved`, with the step's budget left.
Blender records a slider's undo step when it is released, before that timer, and a file may be
saved before it too: undo, redo and opening a file can bring moved cushions back, so handlers
(``settle_restored``) start the timer again whenever a live target's cushions are out of date.

A preset sets five fields but makes one live update: :func:`hold_live_updates` /
:func:`release_live_updates` (the preset menu's ``reset_cb`` / ``post_cb``) hold it back.
"""

import re
import sys
import time

import bpy
import numpy as np

from ....core.constants import CUSHION_LEVEL, LIVE_CUSHION_LEVEL
from ....core.errors import ElliMannError
from ....core.geometry.cushion import cushion_vertices
from ....core.geometry.mesh import icosphere_level
from ....core.pose.posed_pieces import clipped_vertices
from ...bridge.built import built_objects, is_stale
from ...bridge.convert import update_collection_geometry, write_measured, write_mesh_vertices
from ...bridge.selection import part_lookup
from ...services.cushions import rigid_frame
from ...services.rig import split_sources
from ...services.scene import refresh_cushions
from .request import synthesize_request

LIVE_SETTLE_SECONDS = 0.5  # fields still this long: the live target's cushions are rebuilt exactly
LIVE_NAME_KEY = "ellimann_live_name"  # on a live target: the name live updates last gave it

LIVE_STEP_BUDGET = 0.050  # s: a live step with what follows its pieces (pieces_moved), e.g. a preview skin
_followers = []  # called by every live step after its pieces moved (add_follower)
_held = {"depth": 0, "changed": False}  # live updates held back while a preset sets its fields


def on_request_change(self, context):
    if not (self.live and self.target is not None):
        return
    if _held["depth"]:
        _held["changed"] = True
        return
    live_update(context.scene)


def hold_live_updates():
    """Until :func:`release_live_updates`, field changes make no live update (a preset sets five at once)."""
    _held["depth"] += 1


def release_live_updates(scene):
    """End a hold; one live update if a field changed meanwhile. Returns live_update's result or None."""
    _held["depth"] = max(0, _held["depth"] - 1)
    if _held["depth"] or not _held["changed"]:
        return None
    _held["changed"] = False
    props = scene.ellimann_synthesis
    return live_update(scene) if props.live and props.target is not None else None


def live_update(scene):
    """Move the last synthesized mannequin to the current request. Returns seconds taken, or None."""
    props = scene.ellimann_synthesis
    target = props.target
    if target is None or not target.ellimann.is_mannequin:
        return None
    start = time.perf_counter()
    try:
        mannequin, measured, warnings = synthesize_request(props)
        update_collection_geometry(target, mannequin)
        write_measured(target, measured)
        cushions = built_objects(target, "CUSHION")
        if cushions:
            if move_cushions(mannequin, cushions):  # out of date until the fields are still
                _settle_later(scene)
            else:  # rebuilt exactly once; afterwards they move in place
                refresh_cushions(target, min(_level(cushions), LIVE_CUSHION_LEVEL), scene_view_layer(scene))
        rename_live_target(target, mannequin.name)
        pieces_moved(scene, target, mannequin, start)
    except ElliMannError as error:
        props.status = f"Live update failed: {error}"
        return None
    seconds = time.perf_counter() - start
    props.live_ms = seconds * 1e3
    props.status = "; ".join(warnings)
    return seconds


def add_follower(follower):
    """Run ``follower(scene, target, mannequin, seconds_left)`` in every live step once the pieces have moved
    (:func:`pieces_moved`); e.g. a preview skin over them."""
    if follower not in _followers:
        _followers.append(follower)


def remove_follower(follower):
    if follower in _followers:
        _followers.remove(follower)


def pieces_moved(scene, target, mannequin, started):
    """The seam between a live step and what follows its pieces: called once per step, after the ellipsoids and
    the cushions (their halves on a rig too) have moved to ``mannequin``. Each follower gets the seconds left of
    LIVE_STEP_BUDGET (``started``: the step's perf_counter at its start) and is expected to keep within them
    (a coarser preview, or leave the rest to the settle timer)."""
    for follower in list(_followers):
        follower(scene, target, mannequin, LIVE_STEP_BUDGET - (time.perf_counter() - started))


def _level(cushions):
    """The resolution most of the cushions have (CUSHION_LEVEL if none is an icosphere's)."""
    levels = [_hull_level(o)[0] for o in cushions if o.type == "MESH"]
    levels = [level for level in levels if level is not None]
    return max(set(levels), key=levels.count) if levels else CUSHION_LEVEL


def _hull_level(cushion):
    """(the icosphere level of a cushion's hull, the sources of its halves if a rig cut it in two, else None);
    level None: neither a hull as built nor halves of one."""
    split = split_sources(cushion.data)
    return split if split is not None else (icosphere_level(len(cushion.data.vertices)), None)


def move_cushions(mannequin, cushions):
    """Move the built cushions onto ``mannequin``'s ellipsoids by rewriting their vertices in place.

    Needs one cushion per pair, each with a mesh of its own: a hull at an icosphere resolution (as build_cushions
    makes them) or the two halves a rig cut it into (``services.rig``: each half's vertices follow the hull's,
    ``clipped_vertices``); returns False, changing nothing, otherwise. The faces are kept, so the cushions stay out
    of date (``built.is_stale``) until :func:`settle_live` rebuilds them (and cuts them again).
    """
    topology = mannequin.topology
    pairs = np.asarray(topology.cushion_pairs, dtype=int).reshape(-1, 2)
    by_pair = {(o.ellimann.part_name, o.ellimann.partner): o for o in cushions}
    objects = [by_pair.get((topology.names[i], topology.names[j])) for i, j in pairs]
    if len(cushions) != len(pairs) or any(o is None or o.type != "MESH" or o.data.users != 1 for o in objects):
        return False
    hulls = [_hull_level(o) for o in objects]
    if any(level is None for level, _ in hulls):
        return False
    for level in {level for level, _ in hulls}:
        rows = [k for k, (found, _) in enumerate(hulls) if found == level]
        local = cushion_vertices(mannequin.rotation, mannequin.center, mannequin.semi_axes, pairs[rows], level)
        for k, vertices in zip(rows, local):
            obj, first, sources = objects[k], pairs[k, 0], hulls[k][1]
            if sources is not None:
                vertices = clipped_vertices(vertices, sources)
            write_mesh_vertices(obj.data, vertices)
            obj.matrix_world = rigid_frame(mannequin.rotation[first], mannequin.center[first])
    return True


class Debounced:
    """``action(scene)`` once for each scene asked, LIVE_SETTLE_SECONDS after the last ask (every ask restarts the
    wait): what a live update leaves to do once the fields are still. ``timer`` is the function Blender's timer runs
    (kept as one object, so that it can be looked up and unregistered)."""

    def __init__(self, action):
        self.action, self.scenes = action, set()

        def timer():
            names, self.scenes = self.scenes, set()
            for name in sorted(names):
                scene = bpy.data.scenes.get(name)
                if scene is not None:
                    self.action(scene)
            return None  # once

        self.timer = timer

    def later(self, scene):
        """(Re)start the wait for ``scene``."""
        if bpy.app.timers.is_registered(self.timer):
            bpy.app.timers.unregister(self.timer)
        else:  # a file load removes the timer: forget what it was to do in the old file
            self.scenes.clear()
        self.scenes.add(scene.name)
        bpy.app.timers.register(self.timer, first_interval=LIVE_SETTLE_SECONDS)

    def cancel(self):
        if bpy.app.timers.is_registered(self.timer):
            bpy.app.timers.unregister(self.timer)
        self.scenes.clear()


@bpy.app.handlers.persistent
def settle_restored(*_args):
    """undo_post, redo_post and load_post handler: start the settle timer for every scene whose live
    target has out-of-date cushions (moved in place, then recorded in an undo step or saved before the
    timer rebuilt them)."""
    for scene in bpy.data.scenes:
        props = getattr(scene, "ellimann_synthesis", None)
        target = props.target if props is not None and props.live else None
        if target is not None and target.ellimann.is_mannequin and _has_stale(target, built_objects(target, "CUSHION")):
            _settle_later(scene)


HANDLERS = ("undo_post", "redo_post", "load_post")


def settle_live(scene):
    """Rebuild the live target's out-of-date cushions exactly (closed convex hulls).

    Live updates call this through a timer once the fields have been still for LIVE_SETTLE_SECONDS,
    and so does an undo, a redo or opening a file that brings moved cushions back (:func:`settle_restored`).
    The hulls are rebuilt at LIVE_CUSHION_LEVEL (642 vertices; or their own resolution if
    coarser): at Synthesize's 2,562 the rebuild takes seconds on a 40-part mannequin, at 642 about
    half a second. Synthesize again for full-resolution cushions. The ellipsoids the cushions replace
    are hidden in ``scene``'s view layer (:func:`scene_view_layer`), whatever the context's is. Returns
    the number rebuilt (0 if none was out of date, or if they could not be rebuilt: then nothing
    changed, the panel's status says why and so does one line on the console).
    """
    props = scene.ellimann_synthesis
    target = props.target
    if target is None or not target.ellimann.is_mannequin:
        return 0
    cushions = built_objects(target, "CUSHION")
    if not _has_stale(target, cushions):
        return 0
    try:
        refresh_cushions(target, min(_level(cushions), LIVE_CUSHION_LEVEL), scene_view_layer(scene))
    except (ElliMannError, RuntimeError) as error:
        message = " ".join(str(error).split())
        props.status = f"Cushions not rebuilt: {message}"
        print(f"ElliMann: cushions of '{target.name}' not rebuilt: {message}", file=sys.stderr)
        return 0
    return len(built_objects(target, "CUSHION"))


_settling = Debounced(settle_live)  # the scenes whose live targets wait for exact cushions
_settle_later, _settle_timer = _settling.later, _settling.timer


def _has_stale(target, cushions):
    parts = part_lookup(target)
    return any(is_stale(c, parts) for c in cushions)


def scene_view_layer(scene):
    """The view layer ``scene`` is shown in: the context's if it is one of ``scene``'s, else that of a
    window showing ``scene``, else its first. (A timer runs in whatever context the window manager has.)"""
    context = bpy.context
    if context.view_layer is not None and context.view_layer.id_data == scene:
        return context.view_layer
    for window in context.window_manager.windows if context.window_manager else ():
        if window.scene == scene:
            return window.view_layer
    return scene.view_layers[0]


def rename_live_target(target, name):
    """Give the live target the name of its request, without renaming it on every update.

    When another collection holds that name, Blender appends a suffix ("... .001"); the target keeps
    the suffixed name (remembered on it) instead of being renamed again at each update.
    Returns True if it was renamed.
    """
    if target.name == name:
        return False
    suffixed = re.fullmatch(re.escape(name) + r"\.\d{3,}", target.name) is not None
    if suffixed and target.get(LIVE_NAME_KEY) == name and bpy.data.collections.get(name) not in (None, target):
        return False
    target.name = name
    target[LIVE_NAME_KEY] = name
    return True


def register_hooks():
    for name in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if settle_restored not in handlers:
            handlers.append(settle_restored)


def unregister_hooks():
    for name in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if settle_restored in handlers:
            handlers.remove(settle_restored)
    _settling.cancel()
