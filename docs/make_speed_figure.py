#!/usr/bin/env python3
"""docs/images/engine_speed_outputs.png: the 1 Mpix bench frame from the
engine's reference path (float features, every pixel searched every time:
the v0.1 output, the same final energy and guide error as da54119's) beside
the default path (int16 features, converged pixels skipped at the finest
level), with the absolute difference. Top: a crop around the largest sphere
at full size; bottom: the whole frame at a quarter.

    PYTHONPATH=addon /usr/bin/python3 docs/make_speed_figure.py
"""
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "docs"))
sys.path.insert(0, str(ROOT / "bench"))
import tempera  # noqa: E402
from bench_synthesis import benchmark_scene, guide_error  # noqa: E402
from make_engine_figures import labelled_row  # noqa: E402


def run(style, guides, src, tgt, **options):
    image, stats = tempera.synthesize(style, guides, seed=1, **options)
    print(options or "default", "final energy", stats["levels"][-1]["energy"][-1],
          "guide error", guide_error(src, tgt, stats["nnf"]))
    return image


def main(size=1024):
    src, tgt, style = benchmark_scene(size)
    guides = [(a, b, 1.0) for a, b in zip(src, tgt)]
    reference = run(style, guides, src, tgt, feature_precision="float", skip_converged=False)
    default = run(style, guides, src, tgt)
    difference = np.abs(reference - default)
    images = [reference, default, difference]
    s = size
    crops = [img[int(0.22 * s):int(0.22 * s) + 256, int(0.55 * s):int(0.55 * s) + 256] for img in images]
    whole = [img[::4, ::4] for img in images]
    top = labelled_row(crops)
    figure = np.concatenate([top, np.ones((6, top.shape[1], 3), np.float32), labelled_row(whole)], 0)
    out = ROOT / "docs" / "images" / "engine_speed_outputs.png"
    tempera.write_image(str(out), figure)
    print(out)


if __name__ == "__main__":
    main()
