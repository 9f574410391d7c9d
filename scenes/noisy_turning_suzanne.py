"""A scene made the way a new user makes one, only with Blender's own
operators at their defaults (docs/noisy.md, "A scene made by someone else"):
Add > Mesh > Monkey with a Subdivision Surface modifier, turning on its own
axis (two rotation keyframes), Add > Mesh > Torus beside it, a Plane under
both, Add > Light > Sun, and Add > Camera moving sideways (two location
keyframes). No materials are assigned: every object renders Blender's
default surface.

    blender -b --factory-startup --python scenes/noisy_turning_suzanne.py -- --out DIR

writes DIR/turning_suzanne.blend; blender_tests/test_noisy_user_scene.py
builds the same scene with build() and runs Temporal Noise on it.
"""
import argparse
import math
import sys

import bpy

END = 12


def _keyframes(obj, path, first, last):
    """Two keyframes (frames 1 and END), as a user sets them with I."""
    setattr(obj, path, first)
    obj.keyframe_insert(data_path=path, frame=1)
    setattr(obj, path, last)
    obj.keyframe_insert(data_path=path, frame=END)


def build(scene, size=(128, 96)):
    """Builds the scene in `scene` (the window's scene, since the operators
    act on the context); returns (suzanne, torus, camera)."""
    bpy.ops.mesh.primitive_plane_add(size=10)                    # Add > Mesh > Plane
    bpy.ops.mesh.primitive_monkey_add(location=(-0.6, 0, 1))     # Add > Mesh > Monkey
    suzanne = bpy.context.object
    bpy.ops.object.modifier_add(type="SUBSURF")                  # Add Modifier > Subdivision Surface
    bpy.ops.object.shade_smooth()
    _keyframes(suzanne, "rotation_euler", (0, 0, -0.4), (0, 0, 0.6))
    bpy.ops.mesh.primitive_torus_add(location=(1.4, 0.6, 0.4))   # Add > Mesh > Torus
    torus = bpy.context.object
    bpy.ops.object.light_add(type="SUN", rotation=(0.6, 0.3, 0.4))  # Add > Light > Sun
    bpy.ops.object.camera_add(rotation=(math.radians(70), 0, 0))  # Add > Camera
    camera = bpy.context.object
    _keyframes(camera, "location", (-0.3, -6.5, 3.0), (0.5, -6.5, 3.0))
    scene.camera = camera
    scene.frame_start, scene.frame_end = 1, END
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    return suzanne, torus, camera


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="noisy_turning_suzanne.py")
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    scene = bpy.context.scene
    for o in list(scene.objects):
        bpy.data.objects.remove(o)
    build(scene)
    bpy.ops.wm.save_as_mainfile(filepath=f"{args.out}/turning_suzanne.blend")


if __name__ == "__main__":
    main()
