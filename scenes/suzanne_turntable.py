"""A scene made the way a new user makes one, only with Blender's own
operators at their defaults (docs/coherent.md, "A scene made by someone
else"): Add > Mesh > Monkey with a Subdivision Surface modifier and Shade
Smooth, turned by two rotation keyframes (Blender's default Bézier easing);
a cube whose material slot is left empty; a plane for the floor; a sun and an
area light; a camera whose location is keyframed, kept on the monkey by a
Track To constraint. Only the resolution and the frame range are changed from
the defaults (the render engine stays as it is).

    blender -b --factory-startup --python scenes/suzanne_turntable.py -- --out DIR

writes DIR/suzanne_turntable.blend; blender_tests/test_coherent_user_scene.py
builds the same scene with build() and runs the coherent method on it.
"""
import argparse
import math
import sys

import bpy

FRAMES = (1, 16)
SIZE = (96, 72)


def build(scene, size=SIZE):
    """Builds the scene in `scene` (the window's scene: the operators act on
    the context); returns the monkey."""
    bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, -1))
    bpy.ops.mesh.primitive_cube_add(size=1, location=(1.8, 0.8, -0.5))
    bpy.ops.object.material_slot_add()  # a slot with no material in it
    bpy.ops.mesh.primitive_monkey_add(location=(0, 0, 0))
    monkey = bpy.context.object
    bpy.ops.object.modifier_add(type="SUBSURF")
    bpy.ops.object.shade_smooth()
    scene.frame_set(FRAMES[0])
    monkey.keyframe_insert("rotation_euler", frame=FRAMES[0])
    monkey.rotation_euler[2] = math.radians(50)
    monkey.keyframe_insert("rotation_euler", frame=FRAMES[1])
    bpy.ops.object.light_add(type="SUN", location=(3, -3, 5), rotation=(math.radians(40), math.radians(20), 0))
    bpy.ops.object.light_add(type="AREA", location=(-3, -2, 3), rotation=(math.radians(50), math.radians(-40), 0))
    bpy.context.object.data.energy = 200
    bpy.ops.object.camera_add(location=(1.5, -6, 1.5))
    camera = bpy.context.object
    camera.keyframe_insert("location", frame=FRAMES[0])
    camera.location = (-1.2, -5.6, 1.9)
    camera.keyframe_insert("location", frame=FRAMES[1])
    bpy.ops.object.constraint_add(type="TRACK_TO")  # Object Constraints > Track To the monkey
    camera.constraints[-1].target = monkey
    scene.camera = camera
    scene.frame_start, scene.frame_end = FRAMES
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.frame_set(FRAMES[0])
    return monkey


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="suzanne_turntable.py")
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    scene = bpy.context.scene
    for o in list(scene.objects):  # the factory cube, light and camera
        bpy.data.objects.remove(o)
    build(scene)
    bpy.ops.wm.save_as_mainfile(filepath=f"{args.out}/suzanne_turntable.blend")


if __name__ == "__main__":
    main()
