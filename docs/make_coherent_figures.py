#!/usr/bin/env python3
"""Regenerates the pictures of docs/coherent.md in docs/images/.

The shot pictures come from the demo's output (`make demo`: per-frame StyLit
in OUT/frames, the coherent method with two painted keys in OUT/coherent and
OUT/keys); the histogram picture from the procedural panning shot of
bench/bench_tcia.py, with the usage histogram on and off; the layers picture
(Fig. 10) from a procedural square moving over a static background; the
user-scene picture from the folders test_coherent_user_scene.py leaves
(scenes/suzanne_turntable.py: per_frame/, panel/ with the keys, no_keys/).

    make demo
    PYTHONPATH=addon /usr/bin/python3 docs/make_coherent_figures.py --demo out/demo
    PYTHONPATH=addon /usr/bin/python3 docs/make_coherent_figures.py --only layers
    PYTHONPATH=addon /usr/bin/python3 docs/make_coherent_figures.py --only user --user-scene PYTEST_TMP
"""
import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
import tempera  # noqa: E402
from bench_tcia import panning_shot  # noqa: E402
from tempera.methods.tcia import tcia  # noqa: E402

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


def square_shot(w=120, h=72, frames=8, side=28, speed=3):
    """A textured square moving right by `speed` px per frame over a static
    textured background: each surface's guide is its own coordinates in a
    smooth-noise painting (a texture-coordinate AOV). Returns (style, guides,
    frames, square masks, left edge per frame)."""
    rng = np.random.default_rng(7)
    noise = rng.random((100, 160, 3)).astype(np.float32)
    k = np.ones(5) / 5
    for axis in (0, 1, 0, 1):  # blobs a few pixels wide, stretched to full contrast
        noise = np.apply_along_axis(lambda r: np.convolve(r, k, "same"), axis, noise)
    noise = np.clip((noise - noise.mean()) / (4 * noise.std()) + 0.5, 0, 1)
    style = (0.1 + 0.9 * noise * np.array([1.0, 0.85, 0.7], np.float32)).astype(np.float32)
    yy, xx = np.mgrid[0:100, 0:160].astype(np.float32)
    uv = np.stack([xx / 160, yy / 100], -1).astype(np.float32)
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    top, lefts, shot, masks = (h - side) // 2, [], [], []
    for t in range(frames):
        left = 10 + speed * t
        inside = (x >= left) & (x < left + side) & (y >= top) & (y < top + side)
        g = np.where(inside[..., None], np.stack([(125 + x - left) / 160, (60 + y - top) / 100], -1),
                     np.stack([(x + 2) / 160, (y + 2) / 100], -1)).astype(np.float32)
        v = np.zeros((h, w, 2), np.float32)
        v[inside, 0] = speed
        chi = np.ones((h, w), np.float32)
        shot.append(dict(guides=[g], velocity_backward=v, velocity_forward=v, occlusion_backward=chi * (t > 0),
                         occlusion_forward=chi * (t < frames - 1)))
        masks.append(inside.astype(np.float32))
        lefts.append(left)
    return style, [("uv", uv, 4.0)], shot, masks, lefts


def layers_figure():
    """Fig. 10 as rows: the last frame (square's outline in white) and its
    change along the square's motion (black = the paint moved with the
    square), solved as one layer, as the square's layer with the shot's
    motion, and as the square's layer with its motion extended; then the
    composite of the two layers. Returns the change in a band 6 px around
    the square per row."""
    style, guides, frames, masks, lefts = square_shot()
    speed = lefts[1] - lefts[0]
    one = tcia.stylize_shot(style, guides, frames, threads=2)
    layers = [(masks, None), ([1 - m for m in masks], None)]
    plain = tcia.stylize_layers(style, guides, frames, layers[:1], extrapolate=False, threads=2)[0]
    square, rest = tcia.stylize_layers(style, guides, frames, layers, threads=2)
    composite = [tcia.composite([rest[t], square[t]], [1 - masks[t], masks[t]]) for t in range(len(frames))]
    inside = masks[-1] > 0
    grown = np.zeros_like(inside)  # the square grown by 6 px (Chebyshev)
    for dy in range(-6, 7):
        for dx in range(-6, 7):
            grown |= np.roll(np.roll(inside, dy, 0), dx, 1)
    band = grown & ~inside  # just outside the outline, where overpaint would be
    edge = inside & ~(np.roll(inside, 1, 0) & np.roll(inside, -1, 0) & np.roll(inside, 1, 1) & np.roll(inside, -1, 1))
    cells, bands = [], []
    for run in (one, plain, square):
        last = run[-1].copy()
        last[edge] = 1.0
        change = np.abs(run[-1] - np.roll(run[-2], speed, axis=1)).mean(-1)
        cells += [last, np.repeat(np.clip(4 * change, 0, 1)[:, :, None], 3, -1).astype(np.float32)]
        bands.append(float(change[band].mean()))
    cells += [composite[-1], rest[-1]]
    tempera.write_image(str(OUT / "coherent_layers.png"), sheet(cells, 2))
    return bands


USER_SHOWN = (1, 4, 8, 13, 16)  # frames of the user-scene rows; keys at 4 and 13


def user_scene_figure(folder):
    """Rows: per-frame StyLit, the coherent method without keys, with the two
    painted keys (frames 4 and 13), then the keys themselves."""
    rows = [[rgb(folder / run / "frames" / f"frame_{f:04d}.png") for f in USER_SHOWN]
            for run in ("per_frame", "no_keys", "panel")]
    keys = [rgb(folder / "keys" / f"key_{f:04d}.png") for f in (4, 13)]
    blank = np.ones_like(keys[0])
    cells = rows[0] + rows[1] + rows[2] + [blank, keys[0], blank, keys[1], blank]
    tempera.write_image(str(OUT / "coherent_user_scene.png"), sheet(cells, len(USER_SHOWN)))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--demo", default=str(ROOT / "out" / "demo"), help="the demo's output folder")
    parser.add_argument("--only", choices=("shot", "histogram", "layers", "user"), help="make only this picture")
    parser.add_argument("--user-scene", help="the tmp folder of blender_tests/test_coherent_user_scene.py")
    args = parser.parse_args()
    if args.only == "user" or (args.only is None and args.user_scene):
        user_scene_figure(Path(args.user_scene))
    if args.only == "user":
        print(f"pictures in {OUT}")
        return
    if args.only in (None, "shot"):
        shot_figures(Path(args.demo))
    if args.only in (None, "histogram"):
        none, histogram = histogram_figure()
        print(f"blurred usage peak: histogram off {none:.1f}, on {histogram:.1f}")
    if args.only in (None, "layers"):
        one, plain, extended = layers_figure()
        print(f"change along the square's motion, 6 px around it: one layer {one:.4f}, "
              f"layer not extended {plain:.4f}, extended {extended:.4f}")
    print(f"pictures in {OUT}")


if __name__ == "__main__":
    main()
