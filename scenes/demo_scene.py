"""Tempera's demo job, run inside background Blender by tools/run_demo.py:
an end-to-end StyLit stylization (Fišer et al. 2016, thesis ch. 8).

    blender -b --factory-startup --python-exit-code 1 --python scenes/demo_scene.py \
        -- --out out/demo [--addon-zip dist/tempera-addon-X.Y.Z.zip]

1. exemplar (A, A'): builds StyLit's "sphere on a table" scene
   (scenes/exemplar_kit.py), renders its guide passes into
   OUT/exemplar/guides.exr and paints a hatched drawing of it with
   tempera.exemplar_paint (OUT/exemplar/style.png), standing in for the
   artist's painting;
2. target (B): builds the animated scene, a sphere rolling across a table
   past a box under the same light, and renders FRAMES into one multilayer
   EXR per frame (OUT/guides/frame_####.exr);
3. synthesis (B'): for every frame, tempera.synthesize(style, guides) with
   the light-path guides FULL, LDE, LSE and L.*DDE (tempera.stylit_guides)
   of the exemplar and of the frame, StyLit's error-budget patch usage and
   a fixed seed, into OUT/frames/frame_####.png;
4. OUT/contact_sheet.png: the exemplar render above its drawing in the
   first column, then every frame's render above its stylized frame; and
   OUT/exemplar_sheet.png: the exemplar render, its four guides and the drawing.

With --addon-zip the add-on is installed from the zip into a temporary
folder first (as the tests do); without it, the installed `tempera` is used.
Every image is written atomically (a temporary file, then a rename).
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
import exemplar_kit  # noqa: E402
import scene_kit  # noqa: E402

FRAMES = range(1, 9)  # tools/run_demo.py checks for these
RESOLUTION = (320, 240)  # exemplar and frames alike: strokes keep their size
SAMPLES = 32  # per frame; no denoising, the synthesis averages noise out
EXEMPLAR_SAMPLES = 64
SEED = 7  # the drawing and the synthesis of every frame
# Render passes written to the frame EXRs (names as in tempera.passes.PASSES):
# the ones the StyLit guides need, plus Vector and Normal for temporal guides.
GUIDE_PASSES = exemplar_kit.EXEMPLAR_PASSES + ("Vector", "Normal")
# Synthesis settings: the weight of each StyLit guide (all are tone-mapped
# alike, see tempera.stylit_guides, so the weights compare) and of the style
# term (A'/B' colours) against them. LDE counts double: the direct diffuse
# shading is what the drawing's stroke density follows. L.*DDE counts half:
# at SAMPLES it is the noisiest pass. (Measured on the contact sheet: equal
# weights look alike but blur the box's lit and shaded faces together;
# style_weight 2 makes strokes a little crisper and the shading less faithful.)
GUIDE_WEIGHTS = {"FULL": 1.0, "LDE": 2.0, "LSE": 1.0, "L.*DDE": 0.5}
STYLE_WEIGHT = 1.0
FRAMES_PER_ROW = 4  # on the contact sheet


# --------------------------------------------------------------------------- target scene

def build_scene(scene):
    """Table, a sphere rolling across it in FRAMES, a box, the key light, a camera."""
    scene_kit.clear_scene(scene)
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
    for fcurve in sphere.animation_data.action.fcurves:
        for key in fcurve.keyframe_points:
            key.interpolation = "LINEAR"

    scene_kit.add_box(scene, (0.35, 0.55, scene_kit.BOX_SIZE / 2), math.radians(30))

    scene_kit.add_key_light(scene)
    scene_kit.add_camera(scene, location=(0.0, -3.3, 1.7), target=(0, 0.1, 0.2), lens=35)
    scene_kit.set_world(scene)


# --------------------------------------------------------------------------- steps

def read_guides(exr, scene, what):
    """(passes, guides) of one rendered EXR; fails if the render is black."""
    import tempera
    from tempera.passes import channel_names
    from tempera.stylit_guides import read_stylit_passes, stylit_guides

    view_layer = scene_kit.view_layer_name(scene)
    available = set(tempera.image_info(str(exr))["channels"])
    missing = [c for name in exemplar_kit.EXEMPLAR_PASSES for c in channel_names(name, view_layer) if c not in available]
    if missing:
        raise RuntimeError(f"{exr} lacks channels {missing} (it has {sorted(available)})")
    passes = read_stylit_passes(exr, view_layer)
    if passes["Combined"][:, :, :3].mean() < 0.02:
        raise RuntimeError(f"{what} came out black ({exr}); check the scene lighting")
    return passes, stylit_guides(passes)


def make_exemplar(out):
    """Renders and paints the exemplar; returns (render sRGB, style, guides)."""
    import tempera
    from tempera.color import linear_to_srgb
    from tempera.exemplar_paint import paint_hatching

    started = time.monotonic()
    scene = exemplar_kit.build_exemplar_scene()
    exr = exemplar_kit.render_exemplar(scene, out / "exemplar" / "guides.exr", RESOLUTION, EXEMPLAR_SAMPLES)
    rendered = time.monotonic()
    passes, guides = read_guides(exr, scene, "the exemplar")
    style = paint_hatching(passes["Combined"], passes["DiffCol"], seed=SEED)
    tempera.write_image(str(out / "exemplar" / "style.png"), style)
    render = linear_to_srgb(passes["Combined"][:, :, :3])
    tempera.write_image(str(out / "exemplar" / "render.png"), render)
    print(f"exemplar: rendered in {rendered - started:.1f} s, painted in {time.monotonic() - rendered:.1f} s", flush=True)
    return render, style, guides


def render_frames(out):
    """Renders FRAMES of the animated scene; returns (scene, EXR paths)."""
    scene = bpy.context.scene
    build_scene(scene)
    scene_kit.configure_render(scene, RESOLUTION, SAMPLES, GUIDE_PASSES, FRAMES)
    exrs = []
    for i, frame in enumerate(FRAMES, 1):
        started = time.monotonic()
        exrs.append(scene_kit.render_exr(scene, out / "guides" / f"frame_{frame:04d}.exr", frame=frame))
        print(f"render frame {i}/{len(FRAMES)}: {time.monotonic() - started:.1f} s", flush=True)
    return scene, exrs


def stylize_frames(out, scene, exrs, style, exemplar_guides):
    """tempera.synthesize per frame, each on its own (no temporal guide yet);
    returns (renders sRGB, stylized frames, flicker per frame: the mean colour
    change along the rendered motion, see tempera.temporal.flicker)."""
    import tempera
    from tempera import temporal
    from tempera.color import linear_to_srgb
    from tempera.passes import read_pass
    from tempera.synthesis import synthesize

    view_layer = scene_kit.view_layer_name(scene)
    renders, stylized, flickers = [], [], []
    previous = None  # (stylized frame, Vector pass) of the frame before
    for i, (frame, exr) in enumerate(zip(FRAMES, exrs), 1):
        started = time.monotonic()
        passes, guides = read_guides(exr, scene, f"frame {frame}")
        vector = read_pass(exr, "Vector", view_layer)
        pairs = [(source, target, GUIDE_WEIGHTS[name])
                 for (name, source), (_, target) in zip(exemplar_guides, guides)]
        image, stats = synthesize(style, guides=pairs, style_weight=STYLE_WEIGHT, seed=SEED)
        tempera.write_image(str(out / "frames" / f"frame_{frame:04d}.png"), image)
        note = ""
        if previous is not None:
            backward, visible = temporal.motion(vector, previous[1])
            flickers.append(temporal.flicker(previous[0], image, backward, visible))
            note = f", flicker {flickers[-1]:.3f}"
        renders.append(linear_to_srgb(passes["Combined"][:, :, :3]))
        stylized.append(image)
        previous = (image, vector)
        print(f"stylize frame {i}/{len(FRAMES)}: {time.monotonic() - started:.1f} s "
              f"(synthesis {stats.get('seconds', 0):.1f} s, source coverage {stats.get('source_coverage', 0):.0%}"
              f"{note})", flush=True)
    return renders, stylized, flickers


def contact_sheets(out, exemplar_render, style, exemplar_guides, renders, stylized):
    """OUT/contact_sheet.png and OUT/exemplar_sheet.png."""
    import numpy as np
    import tempera

    blank = np.ones_like(style)
    cells = []
    for first in range(0, len(renders), FRAMES_PER_ROW):
        band = slice(first, first + FRAMES_PER_ROW)
        pad = [blank] * (FRAMES_PER_ROW - len(renders[band]))
        head = (exemplar_render, style) if first == 0 else (blank, blank)
        cells += [head[0], *renders[band], *pad, head[1], *stylized[band], *pad]
    sheet = out / "contact_sheet.png"
    tempera.write_image(str(sheet), tempera.contact_sheet(cells, columns=FRAMES_PER_ROW + 1, gap=4, margin=4, background=1.0))

    exemplar_cells = [exemplar_render] + [guide for _, guide in exemplar_guides] + [style]
    exemplar_sheet = out / "exemplar_sheet.png"
    tempera.write_image(str(exemplar_sheet), tempera.contact_sheet(exemplar_cells, columns=3, gap=4, margin=4, background=1.0))
    return sheet, exemplar_sheet


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

    remove_stale(out / "exemplar", "*.exr*")
    remove_stale(out / "exemplar", "*.png")
    remove_stale(out / "guides", "*frame_*.exr*")
    remove_stale(out / "frames", "frame_*.png")

    exemplar_render, style, exemplar_guides = make_exemplar(out)
    exemplar_done = time.monotonic()
    scene, exrs = render_frames(out)
    rendered = time.monotonic()
    renders, stylized, flickers = stylize_frames(out, scene, exrs, style, exemplar_guides)
    stylized_done = time.monotonic()
    sheet, exemplar_sheet = contact_sheets(out, exemplar_render, style, exemplar_guides, renders, stylized)

    print(f"tempera {tempera.__version__} (from {Path(tempera.__file__).parent})")
    print(f"exemplar:       {out / 'exemplar'}/ (guides.exr, render.png, style.png)")
    print(f"guides:         {out / 'guides'}/frame_####.exr ({len(exrs)} frames, {', '.join(GUIDE_PASSES)})")
    print(f"frames:         {out / 'frames'}/frame_####.png (stylized)")
    print(f"contact sheet:  {sheet}")
    print(f"exemplar sheet: {exemplar_sheet}")
    print(f"flicker:        {sum(flickers) / max(1, len(flickers)):.3f} mean colour change along valid motion")
    print(f"exemplar {exemplar_done - started:.1f} s, render {rendered - exemplar_done:.1f} s, "
          f"stylize {stylized_done - rendered:.1f} s, total {time.monotonic() - started:.1f} s")


if __name__ == "__main__":
    main()
