#!/usr/bin/env python3
"""Regenerates the pictures of docs/coherent.md in docs/images/.

The shot pictures come from the demo's output (`make demo`: per-frame StyLit
in OUT/frames, the coherent method with two painted keys in OUT/coherent and
OUT/keys); the histogram picture from the procedural panning shot of
bench/bench_tcia.py, with the usage histogram on and off.

    make demo
    PYTHONPATH=addon /usr/bin/python3 docs/make_coherent_figures.py --demo out/demo
"""
import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
import tempera  # noqa: E402
from bench_tcia import panning_shot  # noqa: E402
from tempera import tcia  # noqa: E402

OUT = ROOT / "docs" / "images"
SHOWN = (1, 4, 7, 10, 12)  # frames of the per-frame / coherent rows
KEYS = (2, 11)  # scenes/demo_scene.py KEY_FRAMES
IN_BETWEEN = 6


def rgb(path):
    return np.clip(tempera.read_image(str(path))[:, :, :3], 0, 1)


def sheet(cells, columns):
    return tempera.contact_sheet(cells, columns=columns, gap=4, margin=4, background=1.0)


def shot_figures(demo):
    per_frame = [rgb(demo / "frames" / f"frame_{f:04d}.png") for f in SHOWN]
    coherent = [rgb(demo / "coherent" / "frames" / f"frame_{f:04d}.png") for f in SHOWN]
    tempera.write_image(str(OUT / "coherent_vs_per_frame.png"), sheet(per_frame + coherent, len(SHOWN)))
    keys = [rgb(demo / "keys" / f"key_{f:04d}.png") for f in KEYS]
    between = rgb(demo / "coherent" / "frames" / f"frame_{IN_BETWEEN:04d}.png")
    tempera.write_image(str(OUT / "coherent_keys.png"), sheet([keys[0], between, keys[1]], 3))


def blurred_usage(image, style):
    """How often each exemplar pixel is used, blurred 5 x 5 (as the histogram
    term sees it): centre output copies pixels, so each output pixel's
    colour names its source."""
    index = {tuple(p): i for i, p in enumerate(style.reshape(-1, style.shape[2]))}
    counts = np.zeros(style.shape[0] * style.shape[1])
    for p in image.reshape(-1, image.shape[2]):
        i = index.get(tuple(p))
        if i is not None:
            counts[i] += 1
    counts = counts.reshape(style.shape[:2])
    k = np.ones(5) / 5  # 5 x 5 box blur: usage of neighbourhoods, as the histogram term sees it
    blurred = np.apply_along_axis(lambda r: np.convolve(r, k, "same"), 0, counts)
    blurred = np.apply_along_axis(lambda r: np.convolve(r, k, "same"), 1, blurred)
    return blurred


def histogram_figure():
    _, guides, frames = panning_shot(160, 3, 3)
    # A painting whose every pixel has its own colour, so that usage can be counted from the output.
    noise = np.random.default_rng(4).random((160, 160, 3)).astype(np.float32)
    style = (0.5 * noise + 0.5 * guides[0][1] / max(1e-6, guides[0][1].max())).astype(np.float32)
    maps = [blurred_usage(tcia.stylize_shot(style, guides, frames, usage=usage, threads=2)[1], style)
            for usage in ("none", "histogram")]
    top = max(m.max() for m in maps)
    # Usage maps over the exemplar, white = the most used spot of either run.
    cells = [style] + [np.repeat((m / top)[:, :, None], 3, -1).astype(np.float32) for m in maps]
    tempera.write_image(str(OUT / "coherent_histogram.png"), sheet(cells, 3))
    return [float(m.max()) for m in maps]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--demo", default=str(ROOT / "out" / "demo"), help="the demo's output folder")
    args = parser.parse_args()
    shot_figures(Path(args.demo))
    none, histogram = histogram_figure()
    print(f"blurred usage peak: histogram off {none:.1f}, on {histogram:.1f}")
    print(f"pictures in {OUT}")


if __name__ == "__main__":
    main()
