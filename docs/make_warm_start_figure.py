"""Makes docs/images/warm_start_user_shot.png from the frames that
bench/bench_warm_start.py --save wrote: rows cold and warm, columns the
given frames, and at the end of each row |frame - previous frame| x 4 of its
last frame (dark = changed). --rows DIR:VARIANT,... puts other runs' frames
in the rows (e.g. an earlier revision's beside this one's); --crop X0,Y0,X1,Y1
shows that part of each frame at --zoom times its size (2) instead of the whole
frame at half; --under R,G,B lays RGBA frames (a fluid's) over that colour.

    PYTHONPATH=addon /usr/bin/python3 docs/make_warm_start_figure.py --frames DIR [--shown 2,12,24] \\
        [--rows DIR:cold,DIR2:cold] [--crop 130,60,290,180] [--zoom 2] [--under 0.4,0.55,0.8] \\
        [--out docs/images/warm_start_user_shot.png]
"""
import argparse
from pathlib import Path

import numpy as np

import tempera

VARIANTS = ("cold", "warm")


def frame(folder, variant, f, under=None):
    image = np.asarray(tempera.read_image(str(Path(folder) / f"{variant}_{f:04d}.png")), np.float32)
    if under is not None and image.shape[2] == 4:
        return image[:, :, :3] * image[:, :, 3:] + np.asarray(under, np.float32) * (1 - image[:, :, 3:])
    return image[:, :, :3]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", help="the folder of the cold and warm rows")
    parser.add_argument("--rows", help="DIR:VARIANT,... instead of --frames' cold and warm")
    parser.add_argument("--shown", default="2,12,24")
    parser.add_argument("--crop", help="X0,Y0,X1,Y1: that part of each frame, at --zoom times its size")
    parser.add_argument("--zoom", type=int, default=2, help="with --crop: the crop's scale")
    parser.add_argument("--under", help="R,G,B (display values): the colour RGBA frames are laid over")
    parser.add_argument("--out", default=str(Path(__file__).resolve().parent / "images" / "warm_start_user_shot.png"))
    args = parser.parse_args()
    shown = [int(f) for f in args.shown.split(",")]
    under = [float(v) for v in args.under.split(",")] if args.under else None
    if args.rows:
        rows = [tuple(row.rsplit(":", 1)) for row in args.rows.split(",")]
    elif args.frames:
        rows = [(args.frames, variant) for variant in VARIANTS]
    else:
        parser.error("give --frames or --rows")
    tiles = []
    for folder, variant in rows:
        images = [frame(folder, variant, f, under) for f in shown]
        change = np.abs(images[-1] - frame(folder, variant, shown[-1] - 1, under))
        tiles += images + [np.clip(1.0 - 4.0 * change.mean(axis=2, keepdims=True).repeat(3, 2), 0, 1)]
    if args.crop:
        x0, y0, x1, y1 = (int(v) for v in args.crop.split(","))
        tiles = [t[y0:y1, x0:x1].repeat(args.zoom, 0).repeat(args.zoom, 1) for t in tiles]
    else:
        tiles = [t[::2, ::2] for t in tiles]
    sheet = tempera.contact_sheet([np.ascontiguousarray(t, np.float32) for t in tiles], columns=len(shown) + 1,
                                  gap=4, margin=4, background=1.0)
    tempera.write_image(args.out, sheet.astype(np.float32))


if __name__ == "__main__":
    main()
