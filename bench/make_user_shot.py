"""A shot made from a scene made by someone else, for the shot benchmarks
(issue 32): dcharata/StyLit's Blender/blend_scenes/lpe_render_a.blend (a
sphere on a floor before a backdrop; fetch dcharata/StyLit, not redistributed
here), lit and painted for StyLit as Creative Flow+ does
(scenes/stylit_setup.py), and a camera that orbits the sphere by `--degrees`
a frame while the key light stays: the sphere's shading, its highlight and
the backdrop move against each other, and the floor and backdrop are
disoccluded at the frame's edge. Saves a new blend; the guides are then
rendered by the guide cache:

    blender -b lpe_render_a.blend --factory-startup --python bench/make_user_shot.py -- \\
        --out /tmp/user_shot.blend [--frames 24] [--degrees 1.5] [--size 600x456]
    tempera render-guides /tmp/user_shot.blend --frames 1-24 --out /tmp/user_shot_guides
"""
import argparse
import math
import sys
from pathlib import Path

import bpy
from mathutils import Matrix, Vector

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "scenes"))
from stylit_setup import set_up_for_stylit  # noqa: E402


def orbit_camera(scene, subject, frames, degrees):
    """Keys the camera on a circle about the subject's vertical axis, looking
    the same way relative to the subject, one key per frame (linear)."""
    camera = scene.camera
    centre = subject.matrix_world @ (sum((Vector(c) for c in subject.bound_box), Vector()) / 8)
    start = camera.matrix_world.copy()
    for i in range(frames):
        turn = (Matrix.Translation(centre) @ Matrix.Rotation(math.radians(degrees * i), 4, "Z")
                @ Matrix.Translation(-centre))
        camera.matrix_world = turn @ start
        camera.keyframe_insert("location", frame=i + 1)
        camera.keyframe_insert("rotation_euler", frame=i + 1)
    for fcurve in camera.animation_data.action.fcurves:
        for key in fcurve.keyframe_points:
            key.interpolation = "LINEAR"


def main():
    parser = argparse.ArgumentParser(prog="make_user_shot.py")
    parser.add_argument("--out", required=True)
    parser.add_argument("--subject", default="Sphere")
    parser.add_argument("--frames", type=int, default=24)
    parser.add_argument("--degrees", type=float, default=1.5)
    parser.add_argument("--size", default="600x456")
    args = parser.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = (int(v) for v in args.size.split("x"))
    scene.render.resolution_percentage = 100
    scene.frame_start, scene.frame_end = 1, args.frames
    scene.render.use_motion_blur = False  # the Vector pass is zero with it
    set_up_for_stylit(scene, args.subject)
    orbit_camera(scene, scene.objects[args.subject], args.frames, args.degrees)
    bpy.ops.wm.save_as_mainfile(filepath=str(Path(args.out).resolve()), copy=True)


main()
