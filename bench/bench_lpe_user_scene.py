"""The tracer against Cycles, object by object, on a scene made by someone else
and set up for StyLit the way Creative Flow+ sets scenes up (issue 35).

    PYTHONPATH=addon blender -b lpe_render_a.blend --factory-startup \\
        --python bench/bench_lpe_user_scene.py -- [--size 600x456] [--samples 128] [--json out.json] \\
        [--picture docs/images/lpe_user_scene.png]
    PYTHONPATH=addon ~/.cache/tempera/venv-bpy45/bin/python bench/bench_lpe_user_scene.py \\
        --blend lpe_render_a.blend [...]

The blend: dcharata/StyLit's Blender/blend_scenes/lpe_render_a.blend (a sphere
on a floor before a backdrop; not redistributed here), lit and painted as
Creative Flow+'s StyLit set-up does (scenes/stylit_setup.py: one soft point
light whose own Max Bounces is 0, a red Diffuse and Glossy mix on the
sphere, the backdrop with Cycles' default surface). The blend's dark world
stays.

Cycles renders it with the guide cache's settings and the tracer traces it,
as blender_tests/test_lpe_gallery.py compares the gallery: FULL, LDE, LSE and
LDDE over the whole image, FULL and LDDE per object. "before" traces the
scene as the exporter wrote it before issue 35 (the lights' Max Bounces and
Multiple Importance ignored).
"""
import argparse
import json
import sys
import tempfile
from pathlib import Path


ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT / "scenes"), str(ROOT / "blender_tests")]

import bpy  # noqa: E402
import numpy as np  # noqa: E402
import test_lpe_gallery as gallery  # noqa: E402
from stylit_setup import set_up_for_stylit  # noqa: E402


def forget_light_settings(scene_dict):
    """The scene as the exporter wrote it before issue 35: no light's own Max
    Bounces or Multiple Importance."""
    for light in scene_dict["lights"]:
        light.pop("max_bounces", None)
        light.pop("multiple_importance", None)


def figures(cycles, traced_buffers):
    whole, _ = gallery.gallery_figures(cycles, traced_buffers)
    out = {"image": {b: list(f) for b, f in whole.items()}}
    for name, (object_figures, _, _) in gallery.object_figures(cycles, traced_buffers).items():
        out[name] = {b: list(f) for b, f in object_figures.items()}
    return out


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    parser = argparse.ArgumentParser(prog="bench_lpe_user_scene.py")
    parser.add_argument("--blend", help="the blend to open (PyPI's bpy); Blender opens it from its command line")
    parser.add_argument("--subject", default="Sphere")
    parser.add_argument("--size", default="600x456")
    parser.add_argument("--samples", type=int, default=gallery.SAMPLES)
    parser.add_argument("--json")
    parser.add_argument("--picture", help="PNG: Cycles' Combined, the tracer's L.*E before, and now")
    args = parser.parse_args(argv)
    if args.blend:
        bpy.ops.wm.open_mainfile(filepath=str(Path(args.blend).resolve()))

    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = (int(v) for v in args.size.split("x"))
    scene.render.resolution_percentage = 100
    light = set_up_for_stylit(scene, args.subject)
    print(f"key light: radius {light['radius']:.2f} m, {light['power']:.0f} W, "
          f"{light['distance']:.2f} m from the camera to the subject")
    with tempfile.TemporaryDirectory() as tmp:
        cycles = gallery.cycles_buffers(scene, tmp, args.samples)
    result = {"blend": Path(bpy.data.filepath).name, "blender": bpy.app.version_string, "size": args.size, "samples": args.samples, "light": light}
    buffers = {}
    for label in ("before", "now"):
        edit = forget_light_settings if label == "before" else None
        buffers[label], _ = gallery.traced_buffers(scene, args.samples, edit=edit)
        result[label] = figures(cycles, buffers[label])
        for region, region_figures in result[label].items():
            for buffer, (error, correlation, r_mean, t_mean) in region_figures.items():
                shown = "empty in Cycles" if error is None else f"mean error {100 * error:5.1f} %, " \
                                                                 f"correlation {correlation:.3f}"
                print(f"{label:6s} {region:10s} {buffer:4s}: Cycles {r_mean:.4f}, tracer {t_mean:.4f}: {shown}")
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1))
    if args.picture:
        write_picture(args.picture, [cycles["FULL"], buffers["before"]["FULL"], buffers["now"]["FULL"]])


def write_picture(path, images):
    """The images side by side in display sRGB, under one gain (Cycles' 99th
    percentile of luminance to 0.8)."""
    import tempera
    from tempera.engine.color import linear_to_srgb

    gain = 0.8 / float(np.percentile(images[0] @ gallery.LUMINANCE, 99))
    tiles = [linear_to_srgb(np.clip(np.nan_to_num(image) * gain, 0, 1)).astype(np.float32) for image in images]
    tempera.write_image(str(path), tempera.contact_sheet(tiles, columns=len(tiles), gap=4, margin=4,
                                                         background=1.0).astype(np.float32))


main()
