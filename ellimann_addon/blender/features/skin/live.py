"""The preview skin of the Synthesize panel's Live updates (the ``pieces_moved`` seam of
``features.synthesize.live``).

With Skin on (``Scene.ellimann_synthesis.skin``), every live step moves the live target's skin with its pieces
(``Skin.following``: each vertex by its pieces' affine motion, no new surface: a few milliseconds of the step's
budget); once the fields have been still for LIVE_SETTLE_SECONDS the skin is made again from the settled pieces at
the preview level (and bound to the armature again), which also makes the first one. Following needs the core Skin
the object was last made from: it is kept in memory by a stamp on the object. After an undo, a redo or opening a file
the stamp may name none: the skin is then left until the fields settle again.
"""

import sys
import uuid

from ....core.errors import ElliMannError
from ....core.job.make import body_skin_maker, make
from ....core.job.request import Request, check
from ....core.mannequin.skin_record import SkinSettings
from ...bridge.convert import collection_to_mannequin
from ...bridge.skin import is_stale_skin, skin_object, write_skin_vertices
from ...services.skin import add_skin
from ..synthesize.live import Debounced, add_follower, remove_follower
from ..synthesize.request import job_of, reference_of, request_of

STAMP_KEY = "ellimann_skin_stamp"  # on a skin object: which core Skin it holds (_made)
KEPT = 8  # core Skins kept in memory (each a few MB at the preview level)
LIVE_LEVEL = "preview"
_made = {}  # stamp -> the core Skin a skin object was made from


def remember(obj, skin):
    """Keep ``skin`` (what ``obj`` now holds) so that live steps can move it with the pieces."""
    stamp = uuid.uuid4().hex
    obj[STAMP_KEY] = stamp
    _made[stamp] = skin
    while len(_made) > KEPT:
        del _made[next(iter(_made))]


def remembered(obj):
    """The core Skin ``obj`` holds, if it is still kept and the mesh was not changed since."""
    skin = _made.get(obj.get(STAMP_KEY))
    if skin is None or obj.type != "MESH" or len(obj.data.vertices) != len(skin.vertices):
        return None
    return skin


def follow(scene, target, mannequin, seconds_left):
    """A live step's follower: the target's skin moved to ``mannequin``, and made again once the fields are still.
    A skin over the pieces moves with them (each vertex by its pieces' motion); a body skin takes the body model's
    blend of the set's bodies for the new request (the correction waits for the fields to be still). Either costs a
    few milliseconds (bench_live_skin), so it is done even when the step has used its budget already
    (``seconds_left`` <= 0: a slow machine): a skin left behind would look broken."""
    props = scene.ellimann_synthesis
    if not props.skin:
        return
    obj = skin_object(target)
    skin = remembered(obj) if obj is not None else None
    if skin is not None and skin.settings.kind == "body":
        vertices, _ = body_skin_maker(reference_of(props)).interpolated(request_of(props))
        write_skin_vertices(obj, vertices)
    elif skin is not None and skin.mannequin.topology.names == mannequin.topology.names:
        write_skin_vertices(obj, skin.following(mannequin).vertices)
    _settle_later(scene)


def settle_skin(scene):
    """Make the live target's skin again, unless it holds it already: the panel's kind (a body skin for the request,
    or the skin over the target's pieces at the preview level). Returns the skin object, or None (nothing to do, or
    it could not be made: the panel's status says why)."""
    props = scene.ellimann_synthesis
    target = props.target
    if not props.skin or target is None or not target.ellimann.is_mannequin:
        return None
    try:
        mannequin = collection_to_mannequin(target)
        obj = skin_object(target)
        if obj is not None and obj.mode != "OBJECT":  # being edited: its mesh is the user's until they leave
            _settle_later(scene)
            return None
        if obj is not None and remembered(obj) is not None and not is_stale_skin(obj, mannequin):
            return None
        settings = SkinSettings.at_level(LIVE_LEVEL, kind=props.skin_kind.lower())
        job = job_of(props, skin=settings)
        if job.skin.kind == "body":  # the request's body skin, over the pieces the target holds
            skin = make(job, bones=True).skin.skin
            skin.mannequin = mannequin.copy(joints=skin.joints)
        else:
            skin = make(check(Request(mannequin=mannequin, skin=job.skin)), bones=True).skin.skin
        obj = add_skin(target, skin)
    except (ElliMannError, RuntimeError) as error:
        message = " ".join(str(error).split())
        props.status = f"Skin not made: {message}"
        print(f"ElliMann: the skin of '{target.name}' not made: {message}", file=sys.stderr)
        return None
    remember(obj, skin)
    return obj


_settling = Debounced(settle_skin)  # the scenes whose live targets' skins wait to be made again
_settle_later, _settle_timer = _settling.later, _settling.timer


def register_hooks():
    add_follower(follow)


def unregister_hooks():
    remove_follower(follow)
    _settling.cancel()
    _made.clear()
