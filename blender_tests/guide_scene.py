"""The tiny animated scene guide-rendering tests use (test_guide_render.py,
test_operator.py): a cube moving right and up with linear keyframes in front
of a static backdrop, a sun and a camera looking along +y."""
import math

import bpy
from mathutils import Vector
from tempera.blender import compat

# 131 x 97 at 50 %: an odd effective width, 65 x 48 pixels.
RESOLUTION, PERCENT, SIZE = (131, 97), 50, (65, 48)
FRAMES = (2, 3, 4)  # keyframes at 1 and 5: linear motion on every rendered frame and its neighbours
CUBE_START, CUBE_STEP = Vector((-1.0, 0.0, -0.4)), Vector((0.5, 0.0, 0.2))  # at frame 1; per frame (right and up)
PARAMS = {"samples": 8, "ld12e_samples": 8}


def cube_mesh(name, size):
    """A new cube mesh of edge `size` centred on its origin."""
    me = bpy.data.meshes.new(name)
    s = size / 2
    verts = [(x, y, z) for x in (-s, s) for y in (-s, s) for z in (-s, s)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    me.from_pydata(verts, [], faces)
    return me


def build_scene(name="Guide render test"):
    scene = bpy.data.scenes.new(name)
    scene.render.engine = compat.eevee_engine()  # saved with EEVEE: guides still come from Cycles
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION
    scene.render.resolution_percentage = PERCENT
    scene.frame_start, scene.frame_end = 1, 5

    def mesh(name, size, location, collection):
        me = cube_mesh(name, size)
        mat = bpy.data.materials.new(name)
        mat.diffuse_color = (0.7, 0.3, 0.2, 1) if name == "MovingCube" else (0.5, 0.5, 0.55, 1)
        me.materials.append(mat)
        obj = bpy.data.objects.new(name, me)
        obj.location = location
        collection.objects.link(obj)
        return obj

    movers = bpy.data.collections.new("Movers")
    scene.collection.children.link(movers)
    backdrop = mesh("Backdrop", 1.0, (0, 3.0, 0), scene.collection)
    backdrop.scale = (30, 0.1, 30)
    cube = mesh("MovingCube", 1.5, CUBE_START, movers)
    for frame, location in ((1, CUBE_START), (5, CUBE_START + 4 * CUBE_STEP)):
        cube.location = location
        cube.keyframe_insert("location", frame=frame)
    for fcurve in compat.action_fcurves(cube):
        for key in fcurve.keyframe_points:
            key.interpolation = "LINEAR"
    cube.location = CUBE_START  # where frame 1 has it

    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (math.radians(60), math.radians(20), 0)
    scene.collection.objects.link(sun)
    camera = bpy.data.objects.new("GuideCamera", bpy.data.cameras.new("GuideCamera"))
    camera.location = (0, -8, 0)
    camera.rotation_euler = (math.radians(90), 0, 0)  # looking along +y
    scene.collection.objects.link(camera)
    scene.camera = camera
    return scene


def remove_scene(scene):
    for obj in list(scene.collection.all_objects):
        bpy.data.objects.remove(obj)
    for coll in list(scene.collection.children_recursive):
        bpy.data.collections.remove(coll)
    bpy.data.scenes.remove(scene)
