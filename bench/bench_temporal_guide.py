#!/usr/bin/env python3
"""StyLit's temporal guide (issue 32): the cost of a frame with it, float
features against the fixed-point ones, side by side in one run.

The temporal guide comes with a per-pixel weight map (occlusion_backward:
no pull where the surface is newly visible). Before 2026-12-05 any weight
map sent the whole level to float features and the generic float distance;
now the fixed-point features stay and only the patches that meet a weighted
pixel are corrected (patch_distance.hpp). `--feature-precision float` is
the old path, so both run here on the same frames, each chained on its own
previous frame, frame after frame alternating:

    PYTHONPATH=addon /usr/bin/python3 bench/bench_temporal_guide.py \\
        --guides out/demo/guides --exemplar build/kit/sphere_on_table/style.png \\
        --exemplar-guides build/kit/sphere_on_table/guides --frames 1-6

Prints per frame and precision: seconds, the finest level's final energy,
flicker (mean colour change along the motion where visible), and how far the
two precisions' frames are apart.
"""
import argparse
import time
from pathlib import Path

import numpy as np

from tempera.app import guide_cache
from tempera.app.frames import parse_frames
from tempera.engine import temporal
from tempera.methods.stylit.stylize import stylize_frame
from tempera import read_image

GUIDES = ["FULL", "LDE", "LSE", "LDDE"]
MOTION = ["velocity_backward", "occlusion_backward"]
PRECISIONS = ("float", "int16")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--guides", required=True)
    parser.add_argument("--exemplar", required=True)
    parser.add_argument("--exemplar-guides", required=True)
    parser.add_argument("--frames", default="1-6")
    parser.add_argument("--temporal", type=float, default=0.5)
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    style = read_image(args.exemplar)[:, :, :3]
    exemplar_frame = int(sorted(Path(args.exemplar_guides).glob("frame_*.exr"))[0].stem.split("_")[1])
    exemplar = guide_cache.read_frame(args.exemplar_guides, exemplar_frame, GUIDES)
    previous = dict.fromkeys(PRECISIONS)
    totals = {p: [0.0, 0.0, 0.0, 0] for p in PRECISIONS}  # seconds, energy, flicker, frames with the guide
    print("| frame | precision | seconds | final energy | flicker | frames apart (mean abs) |")
    print("| ---: | --- | ---: | ---: | ---: | ---: |")
    for frame in parse_frames(args.frames):
        target = guide_cache.read_frame(args.guides, frame, GUIDES + MOTION)
        images = {}
        for precision in PRECISIONS:
            extra = {}
            if previous[precision] is not None:
                extra = dict(previous=previous[precision], velocity_backward=target["velocity_backward"],
                             occlusion_backward=target["occlusion_backward"])
            started = time.monotonic()
            image, stats = stylize_frame(style, exemplar, {k: target[k] for k in GUIDES},
                                         temporal_weight=args.temporal, threads=args.threads,
                                         feature_precision=precision, **extra)
            seconds = time.monotonic() - started
            flicker = (temporal.flicker(previous[precision], image, target["velocity_backward"],
                                        target["occlusion_backward"]) if extra else float("nan"))
            if extra:
                t = totals[precision]
                t[0] += seconds
                t[1] += stats["final_energy"]
                t[2] += flicker
                t[3] += 1
            images[precision] = image
            previous[precision] = image
            apart = np.abs(images["float"] - image).mean() if precision == "int16" else float("nan")
            print(f"| {frame} | {precision} | {seconds:.2f} | {stats['final_energy']:.5g} | {flicker:.4f} | "
                  f"{apart:.4f} |", flush=True)
    print("\nframes with the temporal guide, means:")
    for precision, (seconds, energy, flicker, n) in totals.items():
        if n:
            print(f"  {precision}: {seconds / n:.2f} s, final energy {energy / n:.5g}, flicker {flicker / n:.4f}")


if __name__ == "__main__":
    main()
