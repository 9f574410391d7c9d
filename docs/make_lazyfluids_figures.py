#!/usr/bin/env python3
"""Regenerates docs/images/lazyfluids.png: a smoke-like exemplar whose
contrast grows from left to right (bench_lazyfluids.graded_smoke) carried
around a rotating disc for 40 frames with λ = 3, frames 1, 10, 20 and 40 with
strict uniform usage (top) and with usage none (bottom), over dark grey.

    PYTHONPATH=addon /usr/bin/python3 docs/make_lazyfluids_figures.py
"""
import sys
from pathlib import Path

import numpy as np

import tempera
from tempera.methods.lazyfluids import lazyfluids

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
from bench_lazyfluids import graded_smoke, rotating_disc  # noqa: E402

FRAMES, SHOWN, SIDE, SCALE = 40, (1, 10, 20, 40), 72, 3


def over_grey(rgba):
    a = rgba[..., 3:4]
    return np.kron(rgba[..., :3] * a + 0.2 * (1 - a), np.ones((SCALE, SCALE, 1)))


def row(images, gap=6):
    h = max(i.shape[0] for i in images)
    tiles = []
    for img in images:
        tile = np.ones((h, img.shape[1], 3), np.float32)
        tile[: img.shape[0]] = np.clip(img, 0, 1)
        tiles += [tile, np.ones((h, gap, 3), np.float32)]
    return np.concatenate(tiles[:-1], 1)


def main():
    exemplar = graded_smoke(32)
    alpha, flow = rotating_disc(SIDE, 0.08)
    rows = []
    for usage in ("uniform", "none"):
        frames = lazyfluids.stylize_sequence(exemplar, [alpha] * FRAMES, [flow] * FRAMES, usage=usage,
                                             temporal_weight=3.0, em_iterations=3, threads=2)
        rows.append(row([over_grey(exemplar)] + [over_grey(frames[t - 1]) for t in SHOWN]))
    sheet = np.concatenate([rows[0], np.ones((6, rows[0].shape[1], 3)), rows[1]], 0).astype(np.float32)
    path = ROOT / "docs" / "images" / "lazyfluids.png"
    tempera.write_image(str(path), np.ascontiguousarray(sheet))
    print("wrote", path)


if __name__ == "__main__":
    main()
