#!/usr/bin/env python3
"""Regenerates the engine pictures in docs/images/ from procedural inputs.

    PYTHONPATH=addon /usr/bin/python3 docs/make_engine_figures.py
"""
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
import tempera  # noqa: E402
from bench_synthesis import benchmark_scene  # noqa: E402

OUT = ROOT / "docs" / "images"


def labelled_row(images, gap=6):
    h = max(i.shape[0] for i in images)
    tiles = []
    for img in images:
        rgb = img if img.shape[2] == 3 else np.repeat(img[..., :1], 3, -1)
        tile = np.ones((h, rgb.shape[1], 3), np.float32)
        tile[: rgb.shape[0]] = np.clip(rgb, 0, 1)
        tiles += [tile, np.ones((h, gap, 3), np.float32)]
    return np.concatenate(tiles[:-1], 1)


def usage_modes(size=320):
    src, tgt, style = benchmark_scene(size)
    guides = [(a, b, 1.0) for a, b in zip(src, tgt)]
    results = [tempera.synthesize(style, guides, usage=u, seed=1)[0] for u in ("none", "uniform", "budget")]
    row = labelled_row([style, src[0] / src[0].max(), tgt[0] / tgt[0].max(), *results])
    tempera.write_image(str(OUT / "patch_usage_modes.png"), row)


def blue_yellow(size=96):
    """Thesis Figure 8.7: mostly blue source, mostly yellow target."""
    rng = np.random.default_rng(3)
    tex = 0.15 * rng.random((size, size), dtype=np.float32)
    src_guide = (np.arange(size)[None, :] >= int(0.84 * size)).astype(np.float32).repeat(size, 0)
    tgt_guide = (np.arange(size)[None, :] >= int(0.25 * size)).astype(np.float32).repeat(size, 0)
    yellow = src_guide > 0.5
    style = np.stack([np.where(yellow, 0.85 + tex, tex), np.where(yellow, 0.85 + tex, tex),
                      np.where(yellow, tex, 0.85 + tex)], -1).astype(np.float32)
    guides = [(src_guide, tgt_guide, 2.0)]
    uniform = tempera.synthesize(style, guides, usage="uniform")[0]
    budget = tempera.synthesize(style, guides, usage="budget")[0]
    tempera.write_image(str(OUT / "budget_vs_uniform.png"),
                        labelled_row([style, src_guide[..., None], tgt_guide[..., None], uniform, budget]))


def output_modes(size=200):
    """B' from the same search, made four ways: mean voting blends, the
    others copy exemplar pixels (centre = a warp, Bénard 2013)."""
    src, tgt, style = benchmark_scene(size)
    guides = [(a, b, 1.0) for a, b in zip(src, tgt)]
    results = [tempera.synthesize(style, guides, output=m, seed=1)[0] for m in ("mean", "centre", "mode", "random")]
    tempera.write_image(str(OUT / "output_modes.png"), labelled_row([style, *results]))


def usage_heat(stats, shape):
    uses = np.zeros(shape[:2], np.float32)
    np.add.at(uses, (stats.nnf[..., 1], stats.nnf[..., 0]), 1)
    k = np.exp(-np.arange(-4, 5) ** 2 / (2 * 1.5 ** 2))
    k /= k.sum()
    uses = np.apply_along_axis(lambda r: np.convolve(r, k, "same"), 0, uses)
    uses = np.apply_along_axis(lambda r: np.convolve(r, k, "same"), 1, uses)
    return uses


def histogram_term(size=128):
    """Bénard 2013 Fig. 5 as a measurement: a repetitive exemplar and flat
    guides; plain nearest neighbours pile onto a few tiles (bright spots in
    the blurred usage map), the histogram term spreads them."""
    rng = np.random.default_rng(10)
    tile = rng.random((16, 16, 3), dtype=np.float32)
    style = np.tile(tile, (size // 16, size // 16 * 3 // 2, 1)) + 0.02 * rng.random((size, size * 3 // 2, 3),
                                                                                     dtype=np.float32)
    flat_s = np.full(style.shape[:2], 0.5, np.float32)
    flat_t = np.full((size * 3 // 4, size), 0.5, np.float32)
    row, peaks = [style], []
    for usage in ("none", "histogram"):
        image, stats = tempera.synthesize(style, [(flat_s, flat_t)], usage=usage, seed=1)
        heat = usage_heat(stats, style.shape)
        peaks.append(heat.max())
        row += [image, np.repeat((heat / 12.0)[..., None], 3, -1)]
    tempera.write_image(str(OUT / "histogram_term.png"), labelled_row(row))
    print(f"histogram term: peak blurred usage {peaks[0]:.1f} -> {peaks[1]:.1f}")


if __name__ == "__main__":
    OUT.mkdir(parents=True, exist_ok=True)
    usage_modes()
    blue_yellow()
    output_modes()
    histogram_term()
    print("wrote", *sorted(p.name for p in OUT.glob("*.png")))
