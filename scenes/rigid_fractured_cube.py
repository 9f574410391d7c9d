"""A rigid-body scene made the way a new user makes one, only with
Blender's own operators at their defaults (docs/rigid_bodies.md, "A scene
made by someone else"): a cube broken by the bundled Cell Fracture add-on
(Object > Quick Effects > Cell Fracture, Source: Own Verts, since a fresh
cube has no particles), the shards made rigid with Object > Rigid Body >
Add Active, a plane with Add Passive, the world baked with Bake All
Dynamics, a perspective camera from Add > Camera.

    blender -b --factory-startup --python scenes/rigid_fractured_cube.py -- --out DIR

writes DIR/fractured_cube.blend; blender_tests/test_rigid_user_scene.py
builds the same scene with build() and runs the method on it.
"""
import argparse
import math
import random
import sys

import addon_utils
import bpy
import mathutils

END = 30  # the cube falls, breaks on the floor (frame ~14) and the shards scatter
CAMERA = ((0, -9, 1.2), (math.pi / 2, 0, 0))
FRACTURE_SEED = 1  # the same shards in every run


def _select(objects):
    bpy.ops.object.select_all(action="DESELECT")
    for o in objects:
        o.select_set(True)
    bpy.context.view_layer.objects.active = objects[0]


def has_cell_fracture():
    """Enables the bundled Cell Fracture add-on; False when this Blender has none."""
    return addon_utils.enable("object_fracture_cell", default_set=False) is not None


def build(scene, size=(240, 135)):
    """Builds and bakes the scene in `scene` (the window's scene, since the
    operators act on the context); returns the shards."""
    bpy.ops.mesh.primitive_plane_add(size=20)
    assert bpy.ops.rigidbody.object_add(type="PASSIVE") == {"FINISHED"}  # Rigid Body > Add Passive
    bpy.ops.mesh.primitive_cube_add(size=1, location=(0, 0, 2), rotation=(0, 0.3, 0))
    cube = bpy.context.object
    _select([cube])
    before = set(scene.objects)
    # Cell Fracture jitters its cells with Python's and mathutils' random
    # numbers, unseeded: the shards (and so the bake) differed from run to run.
    random.seed(FRACTURE_SEED)
    mathutils.noise.seed_set(FRACTURE_SEED)
    assert bpy.ops.object.add_fracture_cell_objects(source={"VERT_OWN"}) == {"FINISHED"}
    shards = [o for o in scene.objects if o not in before]
    bpy.data.objects.remove(cube)  # the user deletes the unbroken cube
    _select(shards)
    assert bpy.ops.rigidbody.objects_add(type="ACTIVE") == {"FINISHED"}  # Rigid Body > Add Active, defaults
    scene.frame_start, scene.frame_end = 1, END
    scene.rigidbody_world.point_cache.frame_end = END
    assert bpy.ops.ptcache.bake_all(bake=True) == {"FINISHED"}  # Rigid Body World > Cache > Bake All Dynamics
    bpy.ops.object.camera_add(location=CAMERA[0], rotation=CAMERA[1])  # Add > Camera (perspective)
    scene.camera = bpy.context.object
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    return shards


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="rigid_fractured_cube.py")
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    if not has_cell_fracture():
        sys.exit("rigid_fractured_cube.py: this Blender has no Cell Fracture add-on")
    scene = bpy.context.scene
    for o in list(scene.objects):
        bpy.data.objects.remove(o)
    build(scene)
    bpy.ops.wm.save_as_mainfile(filepath=f"{args.out}/fractured_cube.blend")


if __name__ == "__main__":
    main()
