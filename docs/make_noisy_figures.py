#!/usr/bin/env python3
"""Regenerates the Color Me Noisy pictures of docs/noisy.md: the Temporal
Noise slider at three values side by side, the temporal power spectra of
the tested widths, and a local noise map in use. The medium is the exemplar
kit's coloured-pencil painting (make kit), R the painting itself held still.

    PYTHONPATH=addon /usr/bin/python3 docs/make_noisy_figures.py
"""
from pathlib import Path

import numpy as np

import tempera
from tempera.methods.noisy import noisy
from tempera.engine import temporal

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "images"
PAINTING = ROOT / "build" / "kit" / "sphere_on_table" / "style.png"
THREADS = 2


def row(images, gap=6):
    h = max(i.shape[0] for i in images)
    tiles = []
    for img in images:
        tile = np.ones((h, img.shape[1], 3), np.float32)
        tile[: img.shape[0]] = np.clip(img if img.ndim == 3 else img[..., None], 0, 1)
        tiles += [tile, np.ones((h, gap, 3), np.float32)]
    return np.concatenate(tiles[:-1], 1)


def column(rows, gap=6):
    w = max(r.shape[1] for r in rows)
    out = []
    for r in rows:
        pad = np.ones((r.shape[0], w, 3), np.float32)
        pad[:, : r.shape[1]] = r
        out += [pad, np.ones((gap, w, 3), np.float32)]
    return np.concatenate(out[:-1], 0)


def boil(a, b):
    """|frame 1 - frame 2|, brightened 3x, on white: where the texture boils."""
    return 1 - np.clip(3 * np.abs(a - b).mean(axis=2, keepdims=True).repeat(3, 2), 0, 1)


def slider(style):
    """Rows f = 1.3, 2.2, 4.3: frame 1, frame 2, their difference."""
    rows = []
    for f in (1.3, 2.2, 4.3):
        a, b = (noisy.noisy_frame(style, style, i, noise=f, threads=THREADS) for i in (1, 2))
        rows.append(row([a, b, boil(a, b)]))
    tempera.write_image(str(OUT / "noisy_slider.png"), column(rows))


def local_map(style):
    """A map that is calm (0) on the left and lively (1) on the right, f = 4.3."""
    h, w = style.shape[:2]
    ramp = np.clip((np.arange(w, dtype=np.float32) - 0.35 * w) / (0.3 * w), 0, 1)
    noise_map = np.repeat(ramp[None, :], h, 0)
    a, b = (noisy.noisy_frame(style, style, i, noise=4.3, noise_map=noise_map, threads=THREADS) for i in (1, 2))
    tempera.write_image(str(OUT / "noisy_local_map.png"), row([noise_map, a, boil(a, b)]))


def spectra_svg(style, frames=16):
    """Mean temporal power spectrum per tested f on a still crop (log scale)."""
    crop = np.ascontiguousarray(style[60:132, 110:206])
    curves = {}
    for f in noisy.TESTED_NOISE:
        seq = [noisy.noisy_frame(crop, crop, i, noise=f, threads=THREADS) for i in range(frames)]
        curves[f] = temporal.temporal_power_spectrum(seq)[1:]
        print(f"f = {f}: E = {curves[f].sum():.4f}, flatness {temporal.spectral_flatness(np.r_[0, curves[f]]):.2f}",
              flush=True)
    w, h, left, bottom, top = 560, 300, 60, 40, 20
    lo = np.log10(min(c.min() for c in curves.values()) / 1.5)
    hi = np.log10(max(c.max() for c in curves.values()) * 1.5)
    n = len(next(iter(curves.values())))

    def xy(k, p):
        x = left + (w - left - 110) * k / max(1, n - 1)
        y = top + (h - top - bottom) * (hi - np.log10(p)) / (hi - lo)
        return f"{x:.1f},{y:.1f}"

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" '
             'font-size="11"><rect width="100%" height="100%" fill="white"/>',
             f'<line x1="{left}" y1="{h - bottom}" x2="{w - 110}" y2="{h - bottom}" stroke="black"/>',
             f'<line x1="{left}" y1="{top}" x2="{left}" y2="{h - bottom}" stroke="black"/>',
             f'<text x="{(w - 110 + left) / 2}" y="{h - 8}" text-anchor="middle">temporal frequency '
             f'(cycles per {frames} frames, 1 .. {n})</text>',
             f'<text x="14" y="{h / 2}" transform="rotate(-90 14 {h / 2})" text-anchor="middle">'
             'power (log)</text>']
    for e in range(int(np.ceil(lo)), int(np.floor(hi)) + 1):
        y = xy(0, 10.0 ** e).split(",")[1]
        parts.append(f'<text x="{left - 4}" y="{y}" text-anchor="end">1e{e}</text>')
    for i, (f, c) in enumerate(curves.items()):
        shade = int(200 - 190 * i / (len(curves) - 1))
        colour = f"rgb({255 - shade // 3},{shade // 2},{shade})"
        points = " ".join(xy(k, p) for k, p in enumerate(c))
        parts.append(f'<polyline points="{points}" fill="none" stroke="{colour}" stroke-width="1.6"/>')
        parts.append(f'<text x="{w - 100}" y="{top + 14 * i + 10}" fill="{colour}">f = {f}</text>')
    parts.append("</svg>")
    (OUT / "noisy_spectra.svg").write_text("\n".join(parts) + "\n")


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    style = tempera.read_image(str(PAINTING))[:, :, :3]
    slider(style)
    local_map(style)
    spectra_svg(style)


if __name__ == "__main__":
    main()
