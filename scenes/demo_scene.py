"""Tempera's demo job, run inside background Blender by tools/run_demo.py:
StyLit end to end through the add-on (Fišer et al. 2016, thesis ch. 8).

    blender -b --factory-startup --python-exit-code 1 --python scenes/demo_scene.py \
        -- --out out/demo [--addon-zip dist/tempera-addon-X.Y.Z.zip]

1. builds the animated scene: a sphere rolling across a table past a box,
   under an area light (cast shadows, a highlight on the sphere, light
   bouncing between table, box and sphere), seen by a camera that slowly
   orbits, so both object and camera motion are in the frames;
2. sets Scene.tempera as an artist would in the panel: the bundled exemplar
   kit (the "sphere on a table" render and the project's own coloured-pencil
   painting of it, made by scenes/exemplar_kit.py when the add-on zip is
   built), the default light-path weights and temporal coherence, folders
   under OUT;
3. runs the Stylize Animation operator, bpy.ops.tempera.stylize(): it renders
   the guide cache (OUT/guides/), stylizes every frame (OUT/frames/), writes
   OUT/contact_sheet.png (the painting, then every frame), OUT/stylized.mp4
   and loads the frames into a sequencer scene "Demo Tempera";
4. writes OUT/comparison_sheet.png (the exemplar render and painting, then
   every frame's render above its stylized frame) and saves OUT/demo.blend
   (the scene, its Tempera settings and the result scene) to open in Blender.

With --addon-zip the add-on is installed from the zip into a temporary
folder first (as the tests do); without it, the installed `tempera` is used.
"""
import argparse
import math
import shutil
import sys
import time
from pathlib import Path

import bpy

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tools"))
sys.path.insert(0, str(HERE))
import blender_env  # noqa: E402
import scene_kit  # noqa: E402

FRAMES = range(1, 13)  # tools/run_demo.py checks for these; half a second at 24 fps
RESOLUTION = (320, 240)  # as the bundled exemplar kit: strokes keep their size
SAMPLES = 32  # per guide render; no denoising, the synthesis averages noise out
SCENE_NAME = "Demo"
CAMERA_ORBIT = math.radians(6)  # the camera turns this far around the table over FRAMES
FRAMES_PER_ROW = 6  # on the comparison sheet
NOISE_LEVEL = 4  # the noisy variant: Temporal Noise step 4, f = 2.2 px (docs/noisy.md)
KEY_FRAMES = (2, 11)  # the coherent run's painted keys: segments 1-2, 2-11 and 11-12
COHERENT = "coherent"  # OUT/coherent/: the coherent method's frames, sheet and video
NOISY_RENDER = "noisy_render"  # OUT/noisy_render/noisy/: Temporal Noise as the method, on the render


# --------------------------------------------------------------------------- scene

def _linear_keys(obj):
    from tempera.blender import compat

    for fcurve in compat.action_fcurves(obj):
        for key in fcurve.keyframe_points:
            key.interpolation = "LINEAR"


def build_scene(scene):
    """Table, a sphere rolling across it in FRAMES, a box, the key light and
    an orbiting camera; Cycles at RESOLUTION."""
    scene_kit.clear_scene(scene)
    scene.name = SCENE_NAME
    scene_kit.add_table(scene, half_x=1.6, half_y=1.1)

    radius = scene_kit.SPHERE_RADIUS
    sphere = scene_kit.add_sphere(scene, (0, 0, radius))
    start_x, end_x = -0.9, 0.9
    for i, frame in enumerate(FRAMES):
        x = start_x + (end_x - start_x) * i / (len(FRAMES) - 1)
        sphere.location = (x, -0.15, radius)
        sphere.rotation_euler = (0.0, x / radius, 0.0)  # rolls without slipping
        sphere.keyframe_insert("location", frame=frame)
        sphere.keyframe_insert("rotation_euler", frame=frame)
    _linear_keys(sphere)

    scene_kit.add_box(scene, (0.35, 0.55, scene_kit.BOX_SIZE / 2), math.radians(30))
    scene_kit.add_key_light(scene)

    # The camera orbits the table's centre on a circle through the kit's viewpoint.
    camera = scene_kit.add_camera(scene, location=(0.0, -3.3, 1.7), target=(0, 0.1, 0.2), lens=35)
    pivot = bpy.data.objects.new("Camera orbit", None)
    scene.collection.objects.link(pivot)
    camera.parent = pivot
    for frame, angle in ((FRAMES[0], -CAMERA_ORBIT / 2), (FRAMES[-1], CAMERA_ORBIT / 2)):
        pivot.rotation_euler = (0.0, 0.0, angle)
        pivot.keyframe_insert("rotation_euler", frame=frame)
    _linear_keys(pivot)
    scene_kit.set_world(scene)

    scene.render.engine = "CYCLES"
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION
    scene.render.resolution_percentage = 100
    scene.render.fps = 24
    scene.frame_start, scene.frame_end = FRAMES[0], FRAMES[-1]
    scene.frame_set(FRAMES[0])


def configure_tempera(scene, out):
    """Scene.tempera as an artist sets it in the panel; everything else is the default."""
    settings = scene.tempera
    settings.exemplar_source = "KIT"
    settings.output_dir = str(out)
    settings.guide_dir = str(out / "guides")
    settings.guide_frame_range = "SCENE"
    settings.guide_samples = SAMPLES
    settings.load_result = "SEQUENCER"
    settings.make_video = True


# --------------------------------------------------------------------------- pictures

def comparison_sheet(out, scene):
    """OUT/comparison_sheet.png: the exemplar's render and painting in the
    first column, then each frame's render (the guide cache's FULL, tone
    mapped as the synthesis sees it) above its stylized frame."""
    import numpy as np
    import tempera
    from tempera.app import guide_cache
    from tempera.app import exemplar_kit as kit
    from tempera.engine.guides import tonemap

    style_path, exemplar_guides = kit.kit_exemplar()
    exemplar_render = tempera.read_image(str(style_path.parent / "render.png"))[:, :, :3]
    style = tempera.read_image(str(style_path))[:, :, :3]
    renders = [tonemap(guide_cache.read_frame(out / "guides", f, ["FULL"])["FULL"]) for f in FRAMES]
    stylized = [tempera.read_image(str(out / "frames" / f"frame_{f:04d}.png"))[:, :, :3] for f in FRAMES]
    blank = np.ones_like(style)
    cells = []
    for first in range(0, len(renders), FRAMES_PER_ROW):
        band = slice(first, first + FRAMES_PER_ROW)
        pad = [blank] * (FRAMES_PER_ROW - len(renders[band]))
        head = (exemplar_render, style) if first == 0 else (blank, blank)
        cells += [head[0], *renders[band], *pad, head[1], *stylized[band], *pad]
    sheet = out / "comparison_sheet.png"
    tempera.write_image(str(sheet), tempera.contact_sheet(cells, columns=FRAMES_PER_ROW + 1, gap=4, margin=4,
                                                          background=1.0))
    return sheet


# --------------------------------------------------------------------------- the coherent method

def paint_keys(out):
    """Two painted keyframes made by the project's own stand-in artist: the
    hatching that painted the kit's exemplar (tempera.methods.stylit.exemplar_paint), drawn
    over each key frame's render (the guide cache's FULL) where the scene
    covers the film (alpha; bare paper elsewhere), one seed per frame."""
    import tempera
    from tempera.app import guide_cache
    from tempera.methods.stylit.exemplar_paint import paint_hatching

    keys = out / "keys"
    keys.mkdir(exist_ok=True)
    paths = []
    for frame in KEY_FRAMES:
        g = guide_cache.read_frame(out / "guides", frame, ["FULL", "alpha"])
        path = keys / f"key_{frame:04d}.png"
        tempera.write_image(str(path), paint_hatching(g["FULL"], mask=g["alpha"], seed=frame))
        paths.append((frame, path))
    return paths


def run_coherent(scene, out):
    """Stylize Animation again with Method "Temporally Coherent (Bénard
    2013)" and the two keys imported into the Keyframes list; the guides are
    current, so only the segments run. Returns (per-frame, coherent) mean flicker."""
    from tempera.app import guide_cache
    from tempera import read_image
    from tempera.engine import temporal

    settings = scene.tempera
    settings.method = "TCIA"
    settings.noise_level = 0  # the noisy variant is made once, from the per-frame result
    settings.output_dir = str(out / COHERENT)
    settings.keyframe_dir = str(out / "keys")
    settings.load_result = "NONE"  # 'Demo Tempera' keeps playing the per-frame result
    for frame, path in paint_keys(out):
        if bpy.ops.tempera.import_keyframe(filepath=str(path), frame=frame) != {"FINISHED"}:
            raise RuntimeError(f"Import Key of {path} failed")
    result = bpy.ops.tempera.stylize(mode="ANIMATION")
    if result != {"FINISHED"}:
        raise RuntimeError(f"the coherent Stylize Animation ended with {result}; see the messages above")

    def mean_flicker(folder):
        values = []
        for f in FRAMES[1:]:
            g = guide_cache.read_frame(out / "guides", f, ["velocity_backward", "occlusion_backward"])
            values.append(temporal.flicker(read_image(str(folder / f"frame_{f - 1:04d}.png")),
                                           read_image(str(folder / f"frame_{f:04d}.png")),
                                           g["velocity_backward"], g["occlusion_backward"]))
        return sum(values) / len(values)

    return mean_flicker(out / "frames"), mean_flicker(out / COHERENT / "frames")


def run_noisy_render(scene, out):
    """Stylize Animation with Method "Temporal Noise (Color Me Noisy)": the
    render itself boiled (the paper's 3D case), the Exemplar field empty, so
    the medium is the first render under a paper grain; the guides are
    current, so only the frames run, into out/noisy_render/noisy/frames."""
    settings = scene.tempera
    settings.method = "NOISY"
    settings.media_exemplar = ""
    settings.output_dir = str(out / NOISY_RENDER)
    settings.load_result = "NONE"
    result = bpy.ops.tempera.stylize(mode="ANIMATION")
    if result != {"FINISHED"}:
        raise RuntimeError(f"Stylize Animation with Temporal Noise on the render ended with {result}")


# --------------------------------------------------------------------------- main

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

    out.mkdir(parents=True, exist_ok=True)
    scene = bpy.context.scene
    build_scene(scene)
    configure_tempera(scene, out)
    result = bpy.ops.tempera.stylize(mode="ANIMATION")
    if result != {"FINISHED"}:
        raise RuntimeError(f"Stylize Animation ended with {result}; see the messages above")
    sheet = comparison_sheet(out, scene)
    # The noisy variant, as an artist makes it: Temporal Noise up, Stylize
    # again; the guides and the coherent frames are current, only the noise
    # pass runs (into out/noisy), and its frames become the result shown.
    scene.tempera.noise_level = NOISE_LEVEL
    scene.tempera.make_video = False
    result = bpy.ops.tempera.stylize(mode="ANIMATION")
    if result != {"FINISHED"}:
        raise RuntimeError(f"Stylize Animation with Temporal Noise ended with {result}; see the messages above")
    per_frame, coherent = run_coherent(scene, out)
    run_noisy_render(scene, out)
    blend = out / "demo.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend), check_existing=False)

    print(f"tempera {tempera.__version__} (from {Path(tempera.__file__).parent})")
    print(f"guides:           {out / 'guides'}/frame_####.exr ({len(FRAMES)} frames)")
    print(f"frames:           {out / 'frames'}/frame_####.png (stylized)")
    print(f"noisy variant:    {out / 'noisy'}/frame_####.png (Temporal Noise {NOISE_LEVEL})")
    print(f"contact sheet:    {out / 'contact_sheet.png'}")
    print(f"comparison sheet: {sheet}")
    video = out / "stylized.mp4"
    print(f"video:            {video if video.is_file() else '(none: ffmpeg not found)'}")
    print(f"blend file:       {blend} (scene 'Demo' and the sequencer scene 'Demo Tempera')")
    print(f"coherent:         {out / COHERENT}/frames/frame_####.png (Bénard 2013, keys {out / 'keys'})")
    print(f"mean flicker:     per-frame {per_frame:.4f}, coherent {coherent:.4f}")
    print(f"render boiled:    {out / NOISY_RENDER}/noisy/frames/frame_####.png (Temporal Noise as the method)")
    print(f"total {time.monotonic() - started:.1f} s")


if __name__ == "__main__":
    main()
