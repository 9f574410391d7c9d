"""Building blocks shared by Tempera's scenes built in code (run inside Blender):
the StyLit exemplar (scenes/exemplar_kit.py) and the animated demo
(scenes/demo_scene.py).

Both scenes use the same materials, key light, world and render settings from
here, so that the light-path guides of the exemplar and of the target frames
are comparable (StyLit matches them pixel against pixel).
"""
import os
from pathlib import Path

import bmesh
import bpy
from mathutils import Vector

# Shared look: the exemplar and the demo use these exact values.
TABLE_COLOR, TABLE_ROUGHNESS = (0.62, 0.55, 0.45), 0.55
SPHERE_COLOR, SPHERE_ROUGHNESS = (0.8, 0.12, 0.08), 0.25
SPHERE_RADIUS = 0.3
BOX_COLOR, BOX_ROUGHNESS = (0.12, 0.28, 0.7), 0.45
BOX_SIZE = 0.5
WORLD_COLOR = (0.05, 0.06, 0.08)
# One area light, up and to the front left of the subject, aimed at it.
KEY_LIGHT = {"location": (-1.6, -1.2, 2.4), "target": (0.0, 0.0, 0.0), "energy": 120.0, "size": 1.2}


# --------------------------------------------------------------------------- objects

def new_scene(name):
    """A new, empty scene (its own world), or the existing one of that name emptied."""
    scene = bpy.data.scenes.get(name) or bpy.data.scenes.new(name)
    clear_scene(scene)
    return scene


def clear_scene(scene):
    for obj in list(scene.collection.all_objects):
        bpy.data.objects.remove(obj)
    for collection in (bpy.data.meshes, bpy.data.materials, bpy.data.lights, bpy.data.cameras):
        for block in list(collection):
            if block.users == 0:
                collection.remove(block)


def material(name, color, roughness):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    return mat


def mesh_object(scene, name, build, mat, location, smooth=False):
    """An object whose mesh `build(bm)` fills in, with one material."""
    bm = bmesh.new()
    build(bm)
    mesh = bpy.data.meshes.new(name)
    bm.to_mesh(mesh)
    bm.free()
    for polygon in mesh.polygons:
        polygon.use_smooth = smooth
    mesh.materials.append(mat)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def look_at(obj, target):
    direction = Vector(target) - obj.location
    obj.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()


def add_table(scene, half_x, half_y, name="Table"):
    """A flat rectangle on z = 0, centred on the origin."""

    def build(bm):
        for x, y in ((-half_x, -half_y), (half_x, -half_y), (half_x, half_y), (-half_x, half_y)):
            bm.verts.new((x, y, 0.0))
        bm.faces.new(bm.verts)

    return mesh_object(scene, name, build, material(name, TABLE_COLOR, TABLE_ROUGHNESS), (0, 0, 0))


def add_sphere(scene, location, radius=SPHERE_RADIUS, name="Sphere"):
    return mesh_object(
        scene, name,
        lambda bm: bmesh.ops.create_uvsphere(bm, u_segments=48, v_segments=24, radius=radius),
        material(name, SPHERE_COLOR, SPHERE_ROUGHNESS), location, smooth=True)


def add_box(scene, location, angle_z=0.0, size=BOX_SIZE, name="Box"):
    """A cube of side `size` centred on `location`, turned by `angle_z` radians."""
    box = mesh_object(scene, name, lambda bm: bmesh.ops.create_cube(bm, size=size),
                      material(name, BOX_COLOR, BOX_ROUGHNESS), location)
    box.rotation_euler = (0.0, 0.0, angle_z)
    return box


def add_key_light(scene, offset=(0.0, 0.0, 0.0)):
    """The area light of KEY_LIGHT, shifted by `offset` (light and target alike)."""
    light = bpy.data.objects.new("Key", bpy.data.lights.new("Key", type="AREA"))
    light.data.energy = KEY_LIGHT["energy"]
    light.data.size = KEY_LIGHT["size"]
    light.location = Vector(KEY_LIGHT["location"]) + Vector(offset)
    look_at(light, Vector(KEY_LIGHT["target"]) + Vector(offset))
    scene.collection.objects.link(light)
    return light


def add_camera(scene, location, target, lens):
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.data.lens = lens
    camera.location = location
    look_at(camera, target)
    scene.collection.objects.link(camera)
    scene.camera = camera
    return camera


def set_world(scene, color=WORLD_COLOR):
    world = scene.world or bpy.data.worlds.new(f"{scene.name} world")
    scene.world = world
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (*color, 1.0)
    return world


# --------------------------------------------------------------------------- rendering

def configure_render(scene, resolution, samples, passes, frames=None):
    """Cycles on the CPU with settings that keep the passes clean guides:
    no denoising (it smears the passes differently), no indirect clamping
    (it would bias DiffInd), no motion blur (the Vector pass needs it off),
    a fixed seed; output as a 32-bit multilayer EXR with the given `passes`
    (names as in tempera.app.passes.PASSES) enabled on the first view layer."""
    from tempera.app.passes import PASSES

    unknown = sorted(set(passes) - set(PASSES))
    if unknown:
        raise ValueError(f"unknown render passes {unknown}")
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.sample_clamp_indirect = 0.0
    scene.cycles.seed = 0
    scene.render.use_motion_blur = False
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"  # plain sRGB, as tempera.engine.color
    if frames is not None:
        scene.frame_start, scene.frame_end = frames[0], frames[-1]

    view_layer = scene.view_layers[0]
    for render_pass in PASSES.values():
        setattr(view_layer, render_pass.view_layer_property, render_pass.name in passes)

    settings = scene.render.image_settings
    from tempera.blender import compat  # the add-on is installed (or addon/ on sys.path) wherever this runs

    compat.set_file_format(settings, "OPEN_EXR_MULTILAYER")
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    scene.render.use_file_extension = False


def render_exr(scene, path, frame=None):
    """Renders one frame of `scene` into the multilayer EXR `path`, atomically:
    Blender writes a temporary file next to it, which then replaces `path`."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f".{path.name}.partial")
    if frame is not None:
        scene.frame_set(frame)
    scene.render.filepath = str(partial)
    bpy.ops.render.render(write_still=True, scene=scene.name)
    if not partial.is_file():
        raise RuntimeError(f"Blender did not write {partial}")
    os.replace(partial, path)
    return path


def view_layer_name(scene):
    return scene.view_layers[0].name


# --------------------------------------------------------------------------- shot scripts

def script_out_dir(prog, default):
    """The folder of a shot script's `-- --out DIR` (made, absolute)."""
    import argparse
    import sys

    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog=prog)
    parser.add_argument("--out", default=str(default))
    out = Path(parser.parse_args(argv).out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    return out


def render_shot_guides(scene, frames, folder, params, label):
    """The guide cache of `frames` through the add-on's guide render, its progress printed after `label`."""
    from tempera.blender.guide_render import render_guides

    return render_guides(scene, frames, folder, params,
                         lambda done, total, message: print(f"{label}: guides {done}/{total} {message}", flush=True))


def render_png(scene, path, samples, frame=None):
    """One Cycles frame (no denoising: Debian's Blender has no OpenImageDenoise) as a PNG."""
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.render.image_settings.file_format = "PNG"
    if frame is not None:
        scene.frame_set(frame)
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
