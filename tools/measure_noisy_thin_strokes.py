#!/usr/bin/env python3
"""Thin-stroke retention of Color Me Noisy (docs/noisy.md, "Not done yet"):
the share of R's red-hatching pixels (red above green and blue by 0.15) that
a noisy frame still has, for the default settings and one change at a time.
R is a folder of coherent frames, e.g. the OUT/frames of
blender_tests/test_noisy_user_scene.py or of `make demo`; S is the kit's
painting (make kit).

    PYTHONPATH=addon /usr/bin/python3 tools/measure_noisy_thin_strokes.py --reference DIR --frames 3-5
"""
import argparse
from pathlib import Path

import numpy as np

import tempera
from tempera import noisy

ROOT = Path(__file__).resolve().parent.parent
PAINTING = ROOT / "build" / "kit" / "sphere_on_table" / "style.png"
VARIANTS = [("default (f = 2.2)", {}), ("f = 1.01 (finest level only)", dict(noise=1.01)),
            ("f = 4.3", dict(noise=4.3)), ("no MLS", dict(deform=False)), ("consistency 0", dict(consistency=0.0)),
            ("consistency 8", dict(consistency=8.0)), ("patch 5", dict(patch_size=5)),
            ("patch 3", dict(patch_size=3)), ("centre vote", dict(output="centre"))]


def red(image):
    image = np.asarray(image, np.float32)
    return (image[:, :, 0] > image[:, :, 1] + 0.15) & (image[:, :, 0] > image[:, :, 2] + 0.15)


def rgb(path):
    return np.ascontiguousarray(np.asarray(tempera.read_image(str(path)), np.float32)[:, :, :3])


def main():
    parser = argparse.ArgumentParser(prog="measure_noisy_thin_strokes.py")
    parser.add_argument("--reference", required=True, type=Path)
    parser.add_argument("--frames", required=True, help="A-B")
    parser.add_argument("--exemplar", type=Path, default=PAINTING)
    args = parser.parse_args()
    first, last = map(int, args.frames.split("-"))
    frames = range(first, last + 1)
    style = rgb(args.exemplar)
    references = {f: rgb(args.reference / f"frame_{f:04d}.png") for f in frames}
    strokes = sum(int(red(r).sum()) for r in references.values())
    print(f"R: {strokes / sum(red(r).size for r in references.values()):.4f} of the pixels are red hatching; "
          f"S: {red(style).mean():.4f}")
    for label, values in VARIANTS:
        options = {"noise": 2.2, "threads": 2, **values}
        kept = sum(int(red(noisy.noisy_frame(style, references[f], f, **options)).sum()) for f in frames)
        print(f"{label:30s} red kept {kept / strokes:.2f}")


if __name__ == "__main__":
    main()
