"""The contact sheets of docs/fluids.md's "On Blender's Quick Smoke" and "On
Blender's Quick Liquid", from the outputs of blender_tests/test_quick_smoke.py
(or test_quick_liquid.py, -k quick_liquid) kept by pytest's --basetemp:

    make addon-zip
    blender -b --factory-startup --python-exit-code 1 --python blender_tests/run.py -- \
        --addon-zip dist/tempera-addon-0.1.0.zip -k quick_smoke --basetemp /tmp/quick_smoke
    PYTHONPATH=addon /usr/bin/python3 docs/make_quick_smoke_figure.py /tmp/quick_smoke/quick_smoke0

    PYTHONPATH=addon /usr/bin/python3 docs/make_quick_smoke_figure.py /tmp/quick_smoke/quick_liquid0 \
        --name quick_liquid

writes docs/images/quick_smoke.png (or NAME.png; rows: Cycles' render, LazyFluids with the
smoke still, Fluidymation with the ink video; each over grey) and prints the
alpha IoU of both methods per frame.
"""
import argparse
from pathlib import Path

import numpy as np

import tempera
from tempera.app import guide_cache

IMAGES = Path(__file__).resolve().parent / "images"
GREY = 0.18
ROWS = (("render", "out/lazyfluids/render"), ("LazyFluids", "out/lazyfluids/frames"),
        ("Fluidymation", "out/fluidymation/frames"))


def over_grey(image):
    if image.shape[2] == 3:
        return image
    alpha = image[..., 3:]
    return image[..., :3] * alpha + GREY * (1 - alpha)


def frame_numbers(folder):
    return sorted(int(p.stem.split("_")[1]) for p in folder.glob("frame_*.png"))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("run", type=Path, help="the test's quick_smoke0 (quick_liquid0) folder")
    parser.add_argument("--name", default="quick_smoke", help="the picture's name in docs/images")
    args = parser.parse_args()
    frames = frame_numbers(args.run / ROWS[1][1])
    rows = []
    for name, folder in ROWS:
        images = [tempera.read_image(str(args.run / folder / f"frame_{f:04d}.png")) for f in frames]
        rows.append(np.concatenate([over_grey(i) for i in images], axis=1))
        if name != "render":
            for f, image in zip(frames, images):
                alpha = guide_cache.read_frame(args.run / "guides", f, ["alpha"])["alpha"] > 0.5
                opaque = image[..., 3] > 0.5
                iou = (alpha & opaque).sum() / max((alpha | opaque).sum(), 1)
                print(f"{name} frame {f}: alpha IoU {iou:.3f}")
    IMAGES.mkdir(exist_ok=True)
    path = IMAGES / f"{args.name}.png"
    tempera.write_image(str(path), np.clip(np.concatenate(rows, axis=0), 0, 1), [])
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
