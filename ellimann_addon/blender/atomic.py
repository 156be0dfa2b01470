"""Files Blender itself writes (.blend, .glb, .obj, .png), put in place atomically: ``core.files.atomic_output``
(no bpy), re-exported here for the bpy layer's writers."""

from ..core.files import PROBE_BYTES, atomic_output, blender_write_error  # noqa: F401
