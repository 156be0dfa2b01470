"""The command line's jobs (``core.job``): a request checked whole before any work, its refusal one line naming the
command line's option (``--skin-voxel``, not the core's ``skin_voxel``)."""

from ..core.errors import ElliMannError
from ..core.job.request import NeedsBlenderError, check
from .output import UsageError
from .skin_options import option_named
from .writing import blender_available, no_blender


def checked(request, pose=None, blender_use=None):
    """The job of a ``core.job.request.Request`` checked whole (``core.job.request.check``; ``pose``: its pose
    already read), Blender's writers allowed where bpy can be imported; UsageError (one line) otherwise.
    ``blender_use(kind)``: how the command names an output only Blender writes (default: "writing PATH")."""
    try:
        return check(request, blender=blender_available(), pose=pose)
    except NeedsBlenderError as error:
        raise no_blender(blender_use(error.kind) if blender_use else f"writing {error.path}") from None
    except ElliMannError as error:
        raise UsageError(option_named(error)) from None
