"""Headless Workbench pictures of mannequins: a front line-up with a label under each body (their pieces, or their
skins)."""

import math
import os

import bpy
import numpy as np

from ...core.geometry.ellipsoid import bounds
from ..bridge.convert import mesh_from_arrays
from ..bridge.skin import SKIN_COLOR
from .chatter import blender_output
from .files import atomic_output
from .scene import add_mannequin, empty_scene

BACKGROUND = (1.0, 1.0, 1.0)
LABEL_COLOR = (0.15, 0.15, 0.15, 1.0)
GAP = 0.12  # m between neighbouring bodies


def render_lineup(mannequins, filepath, labels=None, cushions=False, width=2000, skins=None):
    """Render ``mannequins`` side by side, seen from the front, into a PNG ``width`` pixels wide.

    Replaces the current file with an empty scene. Labels (default: the mannequins' names) are text
    objects under the feet. ``skins``: for each mannequin its skin (anything with ``vertices`` and ``faces``, in
    metres) drawn in its place, or None for its pieces. The picture is written atomically; its height follows
    the line-up.
    """
    empty_scene()
    scene = bpy.context.scene
    labels = list(labels) if labels is not None else [m.name for m in mannequins]
    skins = list(skins) if skins is not None else [None] * len(mannequins)
    x = 0.0
    low = np.array([np.inf, np.inf, np.inf])
    high = -low
    for mannequin, label, skin in zip(mannequins, labels, skins):
        if skin is not None:
            lo, hi = np.min(skin.vertices, axis=0), np.max(skin.vertices, axis=0)
        else:
            lo, hi = bounds(mannequin.rotation, mannequin.center, mannequin.semi_axes)
            lo, hi = lo.min(axis=0), hi.max(axis=0)
        offset = np.array([x - lo[0], 0.0, 0.0])
        if skin is not None:
            _add_skin(label, np.asarray(skin.vertices) + offset, skin.faces)
        else:
            add_mannequin(mannequin.translated(offset), cushions=cushions)
        _add_label(label, (x + 0.5 * (hi[0] - lo[0]), lo[1] - 0.2, -0.05))
        low, high = np.minimum(low, lo + offset), np.maximum(high, hi + offset)
        x += hi[0] - lo[0] + GAP
    low[2] -= 0.12  # room for the labels
    _frame_front(scene, low, high, width)
    workbench(scene)
    return write_png(scene, filepath)


def _add_skin(name, vertices, faces):
    mesh = mesh_from_arrays(f"Skin {name}", vertices, faces)
    mesh.shade_smooth()
    obj = bpy.data.objects.new(f"Skin {name}", mesh)
    obj.color = SKIN_COLOR
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _add_label(text, location, size=0.07):
    curve = bpy.data.curves.new(f"Label {text}", type="FONT")
    curve.body = text
    curve.size = size
    curve.align_x = "CENTER"
    curve.align_y = "TOP"
    obj = bpy.data.objects.new(f"Label {text}", curve)
    obj.location = location
    obj.rotation_euler = (math.pi / 2, 0.0, 0.0)  # upright, facing the camera at -Y
    obj.color = LABEL_COLOR
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _frame_front(scene, low, high, pixels, margin=1.06, azimuth=0.0):
    """An orthographic camera framing the box low..high, looking at the body's front from ``azimuth``
    degrees round to its left (0: straight from the front)."""
    camera = bpy.data.objects.new("ElliMann Camera", bpy.data.cameras.new("ElliMann Camera"))
    scene.collection.objects.link(camera)
    camera.data.type = "ORTHO"
    turn = math.radians(azimuth)
    right = np.array([math.cos(turn), math.sin(turn)])  # the picture's x axis, in the floor plane
    corners = np.array([[x, y] for x in (low[0], high[0]) for y in (low[1], high[1])]) @ right
    width, height = corners.max() - corners.min(), high[2] - low[2]
    resolution = (pixels, max(16, round(pixels * height / width)))
    camera.data.sensor_fit = "HORIZONTAL"
    camera.data.ortho_scale = margin * width
    centre = 0.5 * (np.asarray(low) + np.asarray(high))
    back = np.array([math.sin(turn), -math.cos(turn)])  # from the centre towards the camera
    camera.location = (centre[0] + 10.0 * back[0], centre[1] + 10.0 * back[1], centre[2])
    camera.rotation_euler = (math.pi / 2, 0.0, turn)  # at 0 looks along +Y: the body faces -Y
    camera.data.clip_end = 50.0
    scene.camera = camera
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100


def render_view(filepath, low, high, width=800, azimuth=0.0):
    """Workbench picture of the current scene as it is, framing the box low..high (m), written atomically."""
    scene = bpy.context.scene
    _frame_front(scene, low, high, width, azimuth=azimuth)
    workbench(scene)
    return write_png(scene, filepath)


def workbench(scene):
    """Workbench settings of every ElliMann picture (studio light, object colours, cavity, white world,
    PNG); returns the new world."""
    scene.render.engine = "BLENDER_WORKBENCH"
    shading = scene.display.shading
    shading.light = "STUDIO"
    shading.color_type = "OBJECT"
    shading.show_cavity = True
    world = bpy.data.worlds.new("ElliMann Background")
    world.color = BACKGROUND
    scene.world = world
    scene.render.film_transparent = False
    scene.render.image_settings.file_format = "PNG"
    scene.display_settings.display_device = "sRGB"
    scene.view_settings.view_transform = "Standard"
    return world


def write_png(scene, filepath):
    """Render ``scene`` (not necessarily the context's) to ``filepath``, atomically; returns the absolute path."""
    with atomic_output(filepath) as temp, blender_output():
        scene.render.filepath = temp
        bpy.ops.render.render(write_still=True, scene=scene.name)
    return os.path.abspath(filepath)
