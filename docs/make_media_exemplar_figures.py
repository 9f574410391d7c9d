#!/usr/bin/env python3
"""Regenerates the pictures of docs/media_exemplars.md from the project's
own exemplars (tempera.app.media_exemplars; no Blender):

    PYTHONPATH=addon /usr/bin/python3 docs/make_media_exemplar_figures.py

media_smoke_fire.png  the smoke still over dark and light grounds, its alpha,
                      and the fire still over dark;
media_smoke_loop.png  every third frame of a 24-frame smoke loop, over dark;
media_ink.png         the ink drop at frames 1, 6, 12, 18, 24 (2 px/frame),
                      and below each its mask.
"""
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "addon"))
from tempera import contact_sheet, write_image
from tempera.app import media_exemplars  # noqa: E402

OUT = ROOT / "docs" / "images"
SIZE = 192
DARK, LIGHT = np.array([0.08, 0.09, 0.11]), np.array([0.86, 0.88, 0.9])


def over(rgba, ground):
    a = rgba[:, :, 3:4]
    return (rgba[:, :, :3] * a + ground * (1 - a)).astype(np.float32)


def sheet(cells, columns):
    return contact_sheet([np.ascontiguousarray(c, np.float32) for c in cells], columns=columns, gap=4, margin=4,
                         background=1.0)


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    smoke = media_exemplars.smoke_still(SIZE, SIZE, seed=1)
    fire = media_exemplars.smoke_still(SIZE, SIZE, seed=1, kind="fire")
    alpha = np.repeat(smoke[:, :, 3:4], 3, axis=2)
    write_image(str(OUT / "media_smoke_fire.png"),
                sheet([over(smoke, DARK), over(smoke, LIGHT), alpha, over(fire, DARK)], 4))
    loop = media_exemplars.smoke_loop(SIZE, SIZE, 24, seed=1)
    write_image(str(OUT / "media_smoke_loop.png"), sheet([over(f, DARK) for f in loop[::3]], 8))
    frames, masks = media_exemplars.ink_video(SIZE, SIZE, 24, 2.0, seed=1)
    picks = (0, 5, 11, 17, 23)
    cells = [frames[i] for i in picks] + [np.repeat(masks[i][:, :, None], 3, axis=2) for i in picks]
    write_image(str(OUT / "media_ink.png"), sheet(cells, len(picks)))
    print(f"figures in {OUT}")


if __name__ == "__main__":
    main()
