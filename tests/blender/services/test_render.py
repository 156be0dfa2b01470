"""Pictures are written where asked, whatever the name holds."""

import bpy

from ellimann_addon.blender.services.render import write_png


def test_a_hash_in_the_name_is_not_read_as_the_frame_number(tmp_path):
    scene = bpy.context.scene
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 32, 24, 100
    target = tmp_path / "size #1" / "front #2.png"
    assert write_png(scene, target) == str(target)
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in target.parent.iterdir()] == ["front #2.png"]  # no frame-numbered twin, no temporary
