#!/usr/bin/env python3
"""Regenerates the picture of docs/fluidymation.md from a procedural ink
exemplar (no Blender, no outside data):

    PYTHONPATH=addon /usr/bin/python3 docs/make_fluidymation_figures.py

fluidymation.png  row 1: exemplar frames (ink rings spreading on a disc);
                  row 2: the flow made from the target's masks (App. A; hue =
                  direction, brightness = speed); row 3: the output, a
                  growing and drifting ellipse painted with the exemplar,
                  over paper.
"""
import colorsys
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "addon"))
from tempera.methods.fluidymation import fluidymation
from tempera import write_image  # noqa: E402

S, T, FRAMES = 96, 128, 10
OUT = ROOT / "docs" / "images"


def ink_exemplar(n=16):
    yy, xx = np.mgrid[0:S, 0:S].astype(np.float32)
    r = np.hypot(xx - S / 2, yy - S / 2)
    grain = np.random.default_rng(2).random((S, S), dtype=np.float32)
    rgb, masks = [], []
    for i in range(n):
        radius = 8 + 2.4 * i
        edge = np.clip((radius - r) / 6, 0, 1)
        ring = 0.5 + 0.5 * np.sin(2 * np.pi * (radius - r) / 7)
        dark = 0.2 + 0.3 * ring + 0.4 * (1 - edge) + 0.1 * grain  # rings, a dark front, grain
        rgb.append(np.stack([1 - 0.8 * dark, 1 - 0.6 * dark, 1 - 0.3 * dark], -1).astype(np.float32))
        masks.append((r <= radius).astype(np.float32))
    return rgb, masks


def target_masks():
    yy, xx = np.mgrid[0:T, 0:T].astype(np.float32)
    out = []
    for j in range(FRAMES):
        cx, cy, a, b = 48 + 2.5 * j, 64, 18 + 3.0 * j, 12 + 2.0 * j
        out.append((((xx - cx) / a) ** 2 + ((yy - cy) / b) ** 2 <= 1).astype(np.float32))
    return out


def flow_picture(flow, scale=3.0):
    h, w, _ = flow.shape
    out = np.zeros((h, w, 3), np.float32)
    speed = np.hypot(flow[..., 0], flow[..., 1])
    angle = (np.arctan2(flow[..., 1], flow[..., 0]) / (2 * np.pi)) % 1.0
    for y in range(h):
        for x in range(w):
            out[y, x] = colorsys.hsv_to_rgb(angle[y, x], 1.0, min(1.0, speed[y, x] / scale))
    return out


def on_paper(rgb, mask, paper=(0.97, 0.96, 0.92)):
    m = mask[..., None]
    return rgb * m + np.asarray(paper, np.float32) * (1 - m)


def pad_to(img, side):
    out = np.full((side, side, 3), 1.0, np.float32)
    out[: img.shape[0], : img.shape[1]] = img
    return out


def main():
    rgb, masks = ink_exemplar()
    targets = target_masks()
    frames = fluidymation.stylize_sequence(rgb, masks, targets, shape_blur=12)
    flows = fluidymation.flow_from_masks(targets)
    shown = [1, 3, 5, 7, 9]
    rows = [
        [pad_to(on_paper(rgb[int(i * 1.5)], masks[int(i * 1.5)]), T) for i in shown],
        [flow_picture(flows[j]) for j in shown],
        [on_paper(frames[j]["image"], targets[j]) for j in shown],
    ]
    gap = np.ones((T, 4, 3), np.float32)
    lines = [np.concatenate(sum([[c, gap] for c in row], [])[:-1], axis=1) for row in rows]
    hgap = np.ones((4, lines[0].shape[1], 3), np.float32)
    sheet = np.concatenate([lines[0], hgap, lines[1], hgap, lines[2]], axis=0)
    OUT.mkdir(exist_ok=True)
    write_image(str(OUT / "fluidymation.png"), np.clip(sheet, 0, 1).astype(np.float32))
    print(OUT / "fluidymation.png")


if __name__ == "__main__":
    main()
