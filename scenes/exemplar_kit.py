"""StyLit's exemplar scene, "a sphere on a table" (Fišer et al. 2016, §8.3.1),
built in code inside Blender.

One sphere on a table plane, lit by the same area light as the demo scene
(scene_kit.KEY_LIGHT, same direction relative to the sphere), seen by a
closer camera from the demo camera's direction so that the sphere is large in
the frame and its cast shadow, the lit table and the far table edge with the
background behind it are all visible: every illumination effect the demo
frames contain, bar the blue box's colour.

    scene = exemplar_kit.build_exemplar_scene()
    exemplar_kit.render_exemplar(scene, out / "exemplar" / "guides.exr", (320, 240), 64)

VARIANTS add to that scene what the target scenes hold and it lacks
("sphere_and_box": the demo's blue box beside the sphere, for a second
material colour and flat faces). Run as a script, it makes the kit an
artist paints from:

    blender -b --factory-startup --python scenes/exemplar_kit.py -- \
        --variant sphere_on_table --out kit/ [--resolution 320 240] [--samples 64] [--dpi 150]

which writes into kit/: guides.exr (the exemplar's render passes), guides/
(its guide cache, what the synthesis matches), style.png (the project's own
coloured-pencil painting of it), render.png, template.png and template.pdf (the printable painting template
of tempera.methods.stylit.painting_template) and kit.json (variant, resolution and the
template's mark and picture geometry, read by `python -m
tempera.methods.stylit.register_painting`). See docs/exemplar_kit.md.
"""
import argparse
import math
import shutil
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import scene_kit  # noqa: E402

# The passes of the kit's raw render (guides.exr); the light-path guides
# themselves are in the kit's guide cache (guides/).
EXEMPLAR_PASSES = ("Combined", "DiffDir", "DiffCol", "GlossDir", "GlossCol", "DiffInd")
SCENE_NAME = "Tempera exemplar"


def _sphere_on_table(scene):
    scene_kit.add_sphere(scene, (0.0, -0.1, scene_kit.SPHERE_RADIUS))
    return (0.0, -0.1, 0.0)  # the key light's offset: same direction from the sphere as in the demo


def _sphere_and_box(scene):
    scene_kit.add_sphere(scene, (-0.35, -0.15, scene_kit.SPHERE_RADIUS))
    scene_kit.add_box(scene, (0.42, 0.2, scene_kit.BOX_SIZE / 2), math.radians(30))
    return (-0.35, -0.15, 0.0)


# Variant name -> function adding the subject to a scene with a table and
# returning the key light's offset.
VARIANTS = {"sphere_on_table": _sphere_on_table, "sphere_and_box": _sphere_and_box}
DEFAULT_VARIANT = "sphere_on_table"


def build_exemplar_scene(name=SCENE_NAME, variant=DEFAULT_VARIANT):
    """A new scene `name` holding the exemplar `variant` (see VARIANTS); returns it."""
    if variant not in VARIANTS:
        raise ValueError(f"unknown exemplar variant {variant!r}; choose one of {', '.join(VARIANTS)}")
    scene = scene_kit.new_scene(name)
    scene_kit.add_table(scene, half_x=1.6, half_y=1.1)  # as large as the demo table
    light_offset = VARIANTS[variant](scene)
    scene_kit.add_key_light(scene, offset=light_offset)
    scene_kit.add_camera(scene, location=(0.0, -2.0, 1.05), target=(0.0, 0.05, 0.2), lens=42)
    scene_kit.set_world(scene)
    return scene


def render_exemplar(scene, path, resolution, samples):
    """Renders the exemplar's guide passes into the multilayer EXR `path`."""
    scene_kit.configure_render(scene, resolution, samples, EXEMPLAR_PASSES)
    scene.frame_start = scene.frame_end = 1
    return scene_kit.render_exr(scene, path, frame=1)


def render_exemplar_guides(scene, folder, resolution, samples):
    """The exemplar's guide cache (tempera.app.guide_cache, frame 1) in `folder`:
    the guides the synthesis matches, rendered exactly as a target scene's."""
    from tempera.app import guide_cache
    from tempera.blender.guide_render import render_guides

    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    scene.frame_start = scene.frame_end = 1
    params = dict(guide_cache.DEFAULT_PARAMS, samples=samples, ld12e_samples=samples)
    render_guides(scene, [1], folder, params)
    return Path(folder)


def make_kit(out, variant=DEFAULT_VARIANT, resolution=(320, 240), samples=64, dpi=150.0, seed=7):
    """Renders `variant` and writes the kit into the folder `out`; returns the kit.json path.

    Besides what an artist paints from (render, template), the kit holds the
    exemplar's guide cache (guides/) and the project's own painting of it
    (style.png: coloured-pencil hatching whose density and colours follow the
    exemplar's shading, tempera.methods.stylit.exemplar_paint), ready to stylize with."""
    import tempera
    from tempera.engine.color import linear_to_srgb
    from tempera.methods.stylit.exemplar_paint import paint_hatching
    from tempera.methods.stylit.painting_template import make_template, write_kit_json, write_pdf
    from tempera.app.passes import read_pass

    out = Path(out)
    scene = build_exemplar_scene(variant=variant)
    exr = render_exemplar(scene, out / "guides.exr", tuple(resolution), samples)
    view_layer = scene_kit.view_layer_name(scene)
    combined = read_pass(exr, "Combined", view_layer)
    render = linear_to_srgb(combined[:, :, :3])
    tempera.write_image(str(out / "render.png"), render)
    style = paint_hatching(combined, read_pass(exr, "DiffCol", view_layer), seed=seed)
    tempera.write_image(str(out / "style.png"), style)
    render_exemplar_guides(scene, out / "guides", tuple(resolution), samples)
    template = make_template(render, dpi=dpi)
    tempera.write_image(str(out / "template.png"), template.image)
    width, height = resolution
    write_pdf(out / "template.pdf", template.image, template.page_mm,
              caption=f"Tempera exemplar kit: {variant}, {width} x {height}. Paint over the picture; "
                      "keep the four corner marks clean and visible when you photograph or scan it.")
    write_kit_json(out / "kit.json", template, variant=variant, view_layer=view_layer, guides="guides.exr")
    return out / "kit.json"


def main():
    sys.path.insert(0, str(HERE.parent / "tools"))
    import blender_env

    parser = argparse.ArgumentParser(prog="scenes/exemplar_kit.py")
    parser.add_argument("--variant", default=DEFAULT_VARIANT, choices=sorted(VARIANTS))
    parser.add_argument("--out", required=True, help="kit folder to write")
    parser.add_argument("--resolution", type=int, nargs=2, default=(320, 240), metavar=("W", "H"),
                        help="guide resolution (use the target frames' resolution)")
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--dpi", type=float, default=150.0, help="print resolution of the template")
    parser.add_argument("--addon-zip", help="install the add-on from this zip first")
    args = parser.parse_args(blender_env.script_args())
    scripts_dir = blender_env.install_addon_zip(args.addon_zip) if args.addon_zip else None
    if not scripts_dir:
        try:
            import tempera  # noqa: F401  (installed add-on)
        except ImportError:
            sys.path.insert(0, str(blender_env.SOURCE_ADDON_DIR))  # the source tree's, built by make build
    try:
        kit = make_kit(Path(args.out).resolve(), args.variant, args.resolution, args.samples, args.dpi)
    finally:
        if scripts_dir:
            shutil.rmtree(scripts_dir, ignore_errors=True)
    print(f"exemplar kit '{args.variant}': {kit.parent}/ "
          "(guides.exr, guides/, render.png, style.png, template.png, template.pdf, kit.json)")


if __name__ == "__main__":
    main()
