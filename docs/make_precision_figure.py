#!/usr/bin/env python3
"""docs/images/feature_precision.png: the bench's 1 Mpix output with float,
int16 and int8 features side by side (a crop around the largest sphere, and
the whole frame at quarter size), from the images the bench writes:

    for p in float int16 int8; do
      PYTHONPATH=addon /usr/bin/python3 bench/bench_synthesis.py --size 1024 --feature-precision $p
    done
    PYTHONPATH=addon /usr/bin/python3 docs/make_precision_figure.py
"""
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "docs"))
import tempera  # noqa: E402
from make_engine_figures import labelled_row  # noqa: E402

PRECISIONS = ("float", "int16", "int8")


def main(size=1024):
    images = [tempera.read_image(f"/tmp/bench_out_{size}_{p}.png")[..., :3] for p in PRECISIONS]
    s = size
    crops = [img[int(0.22 * s):int(0.22 * s) + 256, int(0.55 * s):int(0.55 * s) + 256] for img in images]
    whole = [img[::4, ::4] for img in images]
    figure = np.concatenate([labelled_row(crops), np.ones((6, labelled_row(crops).shape[1], 3), np.float32),
                             labelled_row(whole)], 0)
    out = ROOT / "docs" / "images" / "feature_precision.png"
    tempera.write_image(str(out), figure)
    print(out)


if __name__ == "__main__":
    main()
