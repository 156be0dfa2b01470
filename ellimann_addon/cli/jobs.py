"""The command line's jobs (``core.job``): a request checked whole before any work, its refusal one line naming the
command line's option (``--skin-voxel``, not the core's ``skin_voxel``)."""

from ..core.errors import ElliMannError
from ..core.job.request import check
from .output import UsageError
from .skinning import option_named
from .writing import blender_available


def checked(request, pose=None):
    """The job of a ``core.job.request.Request`` checked whole (``core.job.request.check``; ``pose``: its pose
    already read), Blender's writers allowed where bpy can be imported; UsageError (one line) otherwise."""
    try:
        return check(request, blender=blender_available(), pose=pose)
    except ElliMannError as error:
        raise UsageError(option_named(error)) from None
