#!/usr/bin/env python3
"""Composites a stylized shot's RGBA frames (straight alpha) over a
background, for the fluid demos (make demo-fluids, docs/media_exemplars.md):

    PYTHONPATH=addon /usr/bin/python3 tools/composite_over.py --over DIR --under DIR_OR_IMAGE \
        --frames 13-36 --out DIR [--video FILE]

DIR/frame_NNNN.png over the background's frame_NNNN.png (a folder) or over
one picture for every frame (a file), into OUT/frame_NNNN.png (each written
to a temporary and renamed), then OUT/contact_sheet.png (every third frame)
and, with --video, an mp4 (when ffmpeg is there). Exit status 2 on a
missing or mismatched frame, naming it.
"""
import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "addon"))
from tempera import contact_sheet, read_image, write_image  # noqa: E402
from tempera.app.frames import parse_frames  # noqa: E402
from tempera.app.video import encode_video  # noqa: E402

FRAME = "frame_{:04d}.png"
SHEET_STEP = 3


def _read(path, channels):
    if not path.is_file():
        raise ValueError(f"{path}: missing")
    image = read_image(str(path))
    if image.ndim != 3 or image.shape[2] < channels:
        raise ValueError(f"{path}: expected at least {channels} channels, got shape {image.shape}")
    return image


def composite(over, under):
    """Straight-alpha RGBA `over` on the RGB(A) `under`: an opaque RGB picture."""
    if over.shape[:2] != under.shape[:2]:
        raise ValueError(f"frame size {over.shape[1]}x{over.shape[0]} differs from the background's "
                         f"{under.shape[1]}x{under.shape[0]}")
    a = over[:, :, 3:4]
    return np.ascontiguousarray(over[:, :, :3] * a + under[:, :, :3] * (1 - a), np.float32)


def run(args):
    frames = parse_frames(args.frames)
    under_dir = Path(args.under).is_dir()
    still = None if under_dir else _read(Path(args.under), 3)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    results = []
    for f in frames:
        under = _read(Path(args.under) / FRAME.format(f), 3) if under_dir else still
        image = composite(_read(Path(args.over) / FRAME.format(f), 4), under)
        write_image(str(out / FRAME.format(f)), image)
        results.append(image)
    write_image(str(out / "contact_sheet.png"),
                contact_sheet(results[::SHEET_STEP], columns=4, gap=4, margin=4, background=1.0))
    if args.video and not encode_video(str(out / "frame_%04d.png"), frames[0], args.video):
        print("composite_over: ffmpeg not found, no video", file=sys.stderr)
    print(f"composite_over: {len(frames)} frames in {out}")
    return 0


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--over", required=True, help="folder of RGBA frames")
    parser.add_argument("--under", required=True, help="folder of background frames, or one picture")
    parser.add_argument("--frames", required=True, help="e.g. 13-36")
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--video", help="also encode this mp4")
    args = parser.parse_args(argv)
    try:
        return run(args)
    except (ValueError, OSError) as exc:
        print(f"composite_over: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
