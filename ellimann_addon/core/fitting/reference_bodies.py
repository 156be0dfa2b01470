"""What a built reference set keeps of its bodies: the bodies themselves (``bodies.npz``, core.synthesis.bodies,
for the body skin) and, from MIN_SPACE_BODIES bodies, their body space (``body_space.npz``,
core.synthesis.body_space, for the ridge body model). Both refuse bad bodies with a BodiesError (one line, naming
the body), which the builder passes on as its own."""

import numpy as np

from ..synthesis.bodies import BodiesError, from_meshes
from ..synthesis.body_space import MIN_SPACE_BODIES, space_from_meshes


def keep_bodies(bodies, labels, fractions):
    """SetBodies of the BodyMesh list ``bodies`` with ``labels`` (BodyLabels); a body without joints takes the
    labels' regressed ones (JointRegressor) when they have one. BodiesError (one line) for bodies without joints or
    that cannot make a body skin (another topology, wrong axes or units)."""
    names, vertices = [body.name for body in bodies], np.stack([body.vertices for body in bodies])
    found = (labels.region, list(labels.region_names), labels.bones, body_joints(bodies, labels), fractions)
    return from_meshes(names, vertices, bodies[0].faces, *found)


def body_joints(bodies, labels):
    """(N, 24, 3) the bodies' joints: each body's own, or the labels' regressed ones (JointRegressor) where it has
    none. BodiesError (one line) naming the bodies with neither."""
    regress = labels.regressor
    joints = [b.joints if b.joints is not None or regress is None else regress(b.vertices) for b in bodies]
    missing = [body.name for body, found in zip(bodies, joints) if found is None]
    if missing:
        raise BodiesError(f"bodies: {', '.join(missing)} have no joints (a body skin is posed on them)")
    return np.stack(joints)


def keep_space(bodies, labels, fractions, progress=None):
    """The BodySpace of the BodyMesh list ``bodies`` (each measured: about half a second a body), or None for fewer
    than MIN_SPACE_BODIES; ``progress(fraction, text)`` as the builder's. BodiesError (one line) for a bad bank."""
    if len(bodies) < MIN_SPACE_BODIES:
        return None

    def tell(done, total, name):
        if progress is not None:
            progress(1.0, f"body space: measured {name} ({done} of {total})")

    return space_from_meshes(
        [body.name for body in bodies],
        np.stack([body.vertices for body in bodies]),
        bodies[0].faces,
        labels.region,
        list(labels.region_names),
        body_joints(bodies, labels),
        fractions,
        tell,
    )
