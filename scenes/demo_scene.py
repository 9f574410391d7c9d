"""Tempera's demo job, run inside background Blender by tools/run_demo.py:

    blender -b --factory-startup --python-exit-code 1 --python scenes/demo_scene.py \
        -- --out out/demo [--addon-zip dist/tempera-addon-X.Y.Z.zip]

1. builds a small animated scene in code: a sphere rolling across a table
   past a box, lit by one area light;
2. renders frames 1-4 with Cycles into one multilayer EXR per frame
   (OUT/guides/frame_####.exr) holding the guide passes Tempera uses;
3. reads the passes back through the native module and writes a derived
   image per frame (OUT/frames/frame_####.png), then OUT/contact_sheet.png.

Step 3 is where stylization will plug in; steps 1 and 2 stay the same.
With --addon-zip the add-on is installed from the zip into a temporary
folder first (as the tests do); without it, the installed `tempera` is used.
"""
import argparse
import math
import shutil
import sys
import time
from pathlib import Path

import bmesh
import bpy
from mathutils import Vector

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tools"))
import blender_env  # noqa: E402

FRAMES = range(1, 5)
RESOLUTION = (160, 120)
SAMPLES = 16
# Render passes written to the guide EXRs (names as in tempera.passes.PASSES).
GUIDE_PASSES = ("Combined", "DiffDir", "DiffCol", "GlossDir", "GlossCol", "DiffInd", "Vector", "Normal")


# --------------------------------------------------------------------------- scene

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


def build_scene(scene):
    """Table, a sphere rolling across it in FRAMES, a box, an area light, a camera."""
    clear_scene(scene)

    def table(bm):
        for x, y in ((-1.6, -1.1), (1.6, -1.1), (1.6, 1.1), (-1.6, 1.1)):
            bm.verts.new((x, y, 0.0))
        bm.faces.new(bm.verts)

    mesh_object(scene, "Table", table, material("Table", (0.62, 0.55, 0.45), 0.55), (0, 0, 0))

    radius = 0.3
    sphere = mesh_object(
        scene, "Sphere",
        lambda bm: bmesh.ops.create_uvsphere(bm, u_segments=48, v_segments=24, radius=radius),
        material("Sphere", (0.8, 0.12, 0.08), 0.25), (0, 0, radius), smooth=True)
    start_x, end_x = -0.9, 0.9
    for i, frame in enumerate(FRAMES):
        x = start_x + (end_x - start_x) * i / (len(FRAMES) - 1)
        sphere.location = (x, -0.15, radius)
        sphere.rotation_euler = (0.0, x / radius, 0.0)  # rolls without slipping
        sphere.keyframe_insert("location", frame=frame)
        sphere.keyframe_insert("rotation_euler", frame=frame)
    for fcurve in sphere.animation_data.action.fcurves:
        for key in fcurve.keyframe_points:
            key.interpolation = "LINEAR"

    box = mesh_object(
        scene, "Box", lambda bm: bmesh.ops.create_cube(bm, size=0.5),
        material("Box", (0.12, 0.28, 0.7), 0.45), (0.35, 0.55, 0.25))
    box.rotation_euler = (0, 0, math.radians(30))

    light = bpy.data.objects.new("Key", bpy.data.lights.new("Key", type="AREA"))
    light.data.energy = 120.0
    light.data.size = 1.2
    light.location = (-1.6, -1.2, 2.4)
    look_at(light, (0, 0, 0))
    scene.collection.objects.link(light)

    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.data.lens = 35
    camera.location = (0.0, -3.3, 1.7)
    look_at(camera, (0, 0.1, 0.2))
    scene.collection.objects.link(camera)
    scene.camera = camera

    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.05, 0.06, 0.08, 1.0)


def configure_render(scene, guides_dir):
    from tempera.passes import PASSES

    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = SAMPLES
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.sample_clamp_indirect = 0.0
    scene.cycles.seed = 0
    scene.render.use_motion_blur = False  # the Vector pass needs it off
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"  # match the plain sRGB PNGs below
    scene.frame_start, scene.frame_end = FRAMES[0], FRAMES[-1]

    view_layer = scene.view_layers[0]
    for render_pass in PASSES.values():
        setattr(view_layer, render_pass.view_layer_property, render_pass.name in GUIDE_PASSES)

    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    scene.render.filepath = str(guides_dir / "frame_####")
    scene.render.use_file_extension = True


def render_guides(scene):
    """Renders FRAMES; returns the multilayer EXR of each frame."""
    bpy.ops.render.render(animation=True, scene=scene.name)
    paths = [Path(scene.render.frame_path(frame=frame)) for frame in FRAMES]
    missing = [str(p) for p in paths if not p.is_file()]
    if missing:
        raise RuntimeError(f"Blender did not write {', '.join(missing)}")
    return paths


# --------------------------------------------------------------------------- processing

def derived_frame(exr):
    """The direct diffuse light path (LDE in Bénard et al. 2013): DiffDir * DiffCol,
    sRGB-encoded for display."""
    import tempera
    from tempera.color import linear_to_srgb
    from tempera.passes import channel_names, read_pass

    view_layer = bpy.context.scene.view_layers[0].name
    available = set(tempera.image_info(str(exr))["channels"])
    for name in GUIDE_PASSES:
        missing = [c for c in channel_names(name, view_layer) if c not in available]
        if missing:
            raise RuntimeError(f"{exr} lacks channels {missing} (it has {sorted(available)})")
    lde = read_pass(exr, "DiffDir", view_layer) * read_pass(exr, "DiffCol", view_layer)
    return linear_to_srgb(lde)


def process_frames(exrs, frames_dir):
    import tempera

    images = []
    for frame, exr in zip(FRAMES, exrs):
        image = derived_frame(exr)
        if image.mean() < 0.02:
            raise RuntimeError(f"frame {frame} came out black ({exr}); check the scene lighting")
        tempera.write_image(str(frames_dir / f"frame_{frame:04d}.png"), image)
        images.append(image)
    return images


# --------------------------------------------------------------------------- main

def remove_stale(folder, pattern):
    folder.mkdir(parents=True, exist_ok=True)
    for path in folder.glob(pattern):
        path.unlink()


def main():
    parser = argparse.ArgumentParser(prog="scenes/demo_scene.py")
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--addon-zip", help="install the add-on from this zip first")
    args = parser.parse_args(blender_env.script_args())

    started = time.monotonic()
    scripts_dir = blender_env.install_addon_zip(args.addon_zip) if args.addon_zip else None
    try:
        run(Path(args.out).resolve(), started)
    finally:
        if scripts_dir:
            shutil.rmtree(scripts_dir, ignore_errors=True)


def run(out, started):
    import tempera

    guides_dir, frames_dir = out / "guides", out / "frames"
    remove_stale(guides_dir, "frame_*.exr")
    remove_stale(frames_dir, "frame_*.png")

    scene = bpy.context.scene
    build_scene(scene)
    configure_render(scene, guides_dir)
    exrs = render_guides(scene)
    rendered = time.monotonic()
    images = process_frames(exrs, frames_dir)
    sheet = out / "contact_sheet.png"
    tempera.write_image(str(sheet), tempera.contact_sheet(images, gap=4, margin=4, background=1.0))

    print(f"tempera {tempera.__version__} (from {Path(tempera.__file__).parent})")
    print(f"guides:        {guides_dir}/frame_####.exr ({len(exrs)} frames, {', '.join(GUIDE_PASSES)})")
    print(f"frames:        {frames_dir}/frame_####.png (DiffDir * DiffCol)")
    print(f"contact sheet: {sheet}")
    print(f"render {rendered - started:.1f} s, processing {time.monotonic() - rendered:.1f} s")


if __name__ == "__main__":
    main()
