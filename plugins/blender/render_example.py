"""Renders the picture in plugins/blender/README.md, headless, with the extension itself:
installs the extension zip, imports a point cloud with Blender's PLY importer, runs
"Reconstruct surface", and renders the result with Cycles on the CPU.

Usage (with PyPI's bpy, Python 3.11):
    python plugins/blender/render_example.py EXTENSION.zip POINTS.ply OUT.png
"""

import os
import sys
import tempfile

_TMP = tempfile.mkdtemp(prefix="vstree-render-")
os.environ["BLENDER_USER_RESOURCES"] = os.path.join(_TMP, "user")
os.environ["XDG_CACHE_HOME"] = os.path.join(_TMP, "cache")

import bpy  # noqa: E402  (the environment must be set before Blender starts)
from mathutils import Vector  # noqa: E402


def main(zip_path, points, out):
    bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
    bpy.ops.wm.read_homefile(use_empty=True)
    # Scanned models are usually Y-up; Blender is Z-up.
    bpy.ops.wm.ply_import(filepath=points, forward_axis="NEGATIVE_Z", up_axis="Y")
    cloud = bpy.context.selected_objects[0]
    bpy.context.view_layer.objects.active = cloud
    bpy.ops.vstree.reconstruct()
    surface = bpy.context.view_layer.objects.active
    cloud.hide_render = True
    for polygon in surface.data.polygons:
        polygon.use_smooth = True
    material = bpy.data.materials.new("clay")
    material.diffuse_color = (0.75, 0.55, 0.4, 1.0)
    surface.data.materials.append(material)

    # Frame the surface: camera on a diagonal, looking at its centre.
    corners = [surface.matrix_world @ Vector(c) for c in surface.bound_box]
    centre = sum(corners, Vector()) / 8
    size = max((c - centre).length for c in corners)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.location = centre + Vector((1.2, -2.2, 0.9)).normalized() * size * 3.2
    camera.rotation_euler = (centre - camera.location).to_track_quat("-Z", "Y").to_euler()
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = 4.0
    sun.rotation_euler = (0.7, 0.2, 0.9)
    for thing in (camera, sun):
        bpy.context.scene.collection.objects.link(thing)
    scene = bpy.context.scene
    scene.camera = camera
    world = bpy.data.worlds.new("world")
    world.color = (0.9, 0.9, 0.92)
    scene.world = world
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 24
    scene.render.resolution_x, scene.render.resolution_y = 640, 480
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True)


if __name__ == "__main__":
    main(*sys.argv[1:4])
