#!/usr/bin/env python3
"""Regenerates the exemplar-kit pictures in docs/images/ (see docs/exemplar_kit.md).

    PYTHONPATH=addon /usr/bin/python3 docs/make_exemplar_kit_figures.py [--kit out/kit/sphere_on_table]

Renders the kit with Blender first if KIT/kit.json is missing. The "artist"
is tempera.methods.stylit.exemplar_paint (hatching, as in the demo); their painting is laid
over the template page, "photographed" upside down in perspective under
uneven light (tempera.methods.stylit.registration.simulate_photo, then JPEG), and
registered back. Writes exemplar_template.png (the page) and
exemplar_registration.png (photo | registered exemplar | the painting as
painted), and prints how close the registered exemplar is (PSNR).
"""
import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
import blender_env  # noqa: E402
import tempera  # noqa: E402
from tempera.methods.stylit.exemplar_paint import paint_hatching  # noqa: E402
from tempera.methods.stylit.painting_template import place_picture, read_kit_json  # noqa: E402
from tempera.app.passes import read_pass  # noqa: E402
from tempera.methods.stylit.registration import estimate_homography, register_painting, simulate_photo  # noqa: E402

OUT = ROOT / "docs" / "images"


def shrink(image, factor):
    """Box-average by an integer factor (for small pictures of large pages)."""
    h, w = image.shape[0] // factor, image.shape[1] // factor
    return image[: h * factor, : w * factor].reshape(h, factor, w, factor, -1).mean(axis=(1, 3))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--kit", default=str(ROOT / "out" / "kit" / "sphere_on_table"))
    parser.add_argument("--blender", default="blender")
    args = parser.parse_args()
    kit_dir = Path(args.kit)
    if not (kit_dir / "kit.json").is_file():
        subprocess.run(blender_env.blender_command(args.blender, ROOT / "scenes" / "exemplar_kit.py",
                                                   ["--variant", "sphere_on_table", "--out", kit_dir]), check=True)
    kit = read_kit_json(kit_dir / "kit.json")
    page = tempera.read_image(str(kit_dir / "template.png"))[:, :, :3].astype(np.float64)
    exr = kit_dir / kit["guides"]
    painting = paint_hatching(read_pass(exr, "Combined", kit["view_layer"]),
                              read_pass(exr, "DiffCol", kit["view_layer"]), seed=7)
    painted = place_picture(page.copy(), kit["picture"], painting)

    # Upside down, in perspective, on a 1600 x 1200 photo.
    h, w = page.shape[:2]
    quad = [(1480, 1110), (140, 1040), (190, 110), (1420, 160)]  # page TL, TR, BR, BL in the photo
    to_photo = estimate_homography(np.array([[0, 0], [w, 0], [w, h], [0, h]], float), np.array(quad, float))
    photo_path = kit_dir / "simulated_photo.jpg"
    tempera.write_image(str(photo_path), simulate_photo(painted, to_photo, (1600, 1200), seed=1, noise=0.015))
    photo = tempera.read_image(str(photo_path))
    style = register_painting(photo, kit)
    error = np.mean((style[2:-2, 2:-2] - painting[2:-2, 2:-2]) ** 2)
    print(f"registered {photo_path}: PSNR {10 * np.log10(1 / error):.1f} dB against the painting")

    OUT.mkdir(parents=True, exist_ok=True)
    tempera.write_image(str(OUT / "exemplar_template.png"), shrink(page, 3).astype(np.float32))
    gap = np.ones((240, 6, 3), np.float32)
    row = np.concatenate([shrink(photo[:, :, :3], 5), gap, style, gap, painting], axis=1)
    tempera.write_image(str(OUT / "exemplar_registration.png"), row.astype(np.float32))


if __name__ == "__main__":
    main()
