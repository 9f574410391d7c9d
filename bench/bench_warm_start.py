#!/usr/bin/env python3
"""StyLit along a shot, cold against warm-started frames, side by side in one
run (issue 32). Each variant is chained on its own previous frame (the
temporal guide, and for the warm start the previous frame's matches advected
along the rendered motion); frame after frame the variants alternate, so both
see the same machine load.

    PYTHONPATH=addon /usr/bin/python3 bench/bench_warm_start.py --guides GUIDE_CACHE \\
        --exemplar PAINTING (--exemplar-guides GUIDE_CACHE | --exemplar-pngs DIR) [--frames 1-8] \\
        [--exemplar-shrink 2] [--temporal 0.5] [--variants cold,warm] [--json out.json] [--save DIR]

--exemplar-pngs reads StyLit guides rendered elsewhere as display PNGs in
ebsynth's naming (jamriska/ebsynth examples/stylit: source_fullgi.png,
source_dirdif.png, source_dirspc.png, source_indirb.png for FULL, LDE, LSE,
LDDE), undoing the guide tone map (x / (1 + x), then sRGB) so that Tempera's
tone map gives back their values.

Per frame and variant: seconds, the finest level's final energy (the
solver's objective), warp error (mean colour change along the motion where
visible: the flicker), detail (mean gradient magnitude of the frame) and how
far the variant's frame is from the cold one's. Means over the frames after
the first (the ones a warm start changes).
"""
import argparse
import json
import time
from pathlib import Path

import numpy as np

from tempera import read_image, write_image
from tempera.app import guide_cache
from tempera.app.frames import parse_frames
from tempera.engine import temporal
from tempera.engine.color import srgb_to_linear
from tempera.methods.stylit.stylize import stylize_frame

GUIDES = ["FULL", "LDE", "LSE", "LDDE"]
MOTION = ["velocity_backward", "occlusion_backward"]
EBSYNTH_PNGS = {"FULL": "source_fullgi.png", "LDE": "source_dirdif.png", "LSE": "source_dirspc.png",
                "LDDE": "source_indirb.png"}
VARIANTS = {"cold": {"warm_start": "off"}, "warm": {"warm_start": "on"}}


def exemplar_from_pngs(folder):
    """Linear guides whose tone map gives back the PNGs' display values."""
    out = {}
    for name, file in EBSYNTH_PNGS.items():
        display = np.asarray(read_image(str(Path(folder) / file)), np.float32)[:, :, :3]
        d = np.clip(srgb_to_linear(display), 0.0, 0.999)
        out[name] = (d / (1.0 - d)).astype(np.float32)
    return out


def shrink(image, k):
    """Box average over k x k blocks (the edge rows and columns that do not fill one dropped)."""
    h, w = image.shape[0] // k * k, image.shape[1] // k * k
    return image[:h, :w].reshape(h // k, k, w // k, k, -1).mean(axis=(1, 3)).astype(np.float32)


def detail(image):
    """Mean gradient magnitude: what a smeared or washed-out frame loses."""
    gy, gx = np.gradient(image.mean(axis=2))
    return float(np.hypot(gx, gy).mean())


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--guides", required=True)
    parser.add_argument("--exemplar", required=True)
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--exemplar-guides")
    source.add_argument("--exemplar-pngs")
    parser.add_argument("--exemplar-shrink", type=int, default=1,
                        help="box-downsample the painting and its guides by this integer factor")
    parser.add_argument("--frames", default="1-8")
    parser.add_argument("--temporal", type=float, default=0.5)
    parser.add_argument("--variants", default="cold,warm")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--json")
    parser.add_argument("--save", help="folder: each variant's frames as VARIANT_NNNN.png")
    args = parser.parse_args()
    variants = args.variants.split(",")
    style = np.asarray(read_image(args.exemplar), np.float32)[:, :, :3]
    if args.exemplar_pngs:
        exemplar = exemplar_from_pngs(args.exemplar_pngs)
    else:
        frame = int(sorted(Path(args.exemplar_guides).glob("frame_*.exr"))[0].stem.split("_")[1])
        exemplar = guide_cache.read_frame(args.exemplar_guides, frame, GUIDES)
    if args.exemplar_shrink > 1:
        style = shrink(style, args.exemplar_shrink)
        exemplar = {k: shrink(v, args.exemplar_shrink) for k, v in exemplar.items()}
    state = {v: {} for v in variants}  # previous image and field per variant
    rows = []
    print("| frame | variant | seconds | final energy | warp error | detail | apart from cold |")
    print("| ---: | --- | ---: | ---: | ---: | ---: | ---: |")
    for frame in parse_frames(args.frames):
        target = guide_cache.read_frame(args.guides, frame, GUIDES + MOTION)
        images = {}
        for variant in variants:
            prev = state[variant]
            extra = {}
            if prev:
                extra = dict(previous=prev["image"], previous_field=prev["field"],
                             velocity_backward=target["velocity_backward"],
                             occlusion_backward=target["occlusion_backward"])
            started = time.monotonic()
            image, stats = stylize_frame(style, exemplar, {k: target[k] for k in GUIDES},
                                         temporal_weight=args.temporal, threads=args.threads,
                                         **VARIANTS[variant.rstrip("0123456789")], **extra)
            seconds = time.monotonic() - started
            warp = (temporal.flicker(prev["image"], image, target["velocity_backward"],
                                     target["occlusion_backward"]) if prev else float("nan"))
            images[variant] = image
            if args.save:
                Path(args.save).mkdir(parents=True, exist_ok=True)
                write_image(str(Path(args.save) / f"{variant}_{frame:04d}.png"), np.clip(image, 0, 1))
            state[variant] = {"image": image, "field": stats["field"]}
            apart = float(np.abs(images["cold"] - image).mean()) if "cold" in images else float("nan")
            row = dict(frame=frame, variant=variant, seconds=seconds, energy=stats["final_energy"], warp=warp,
                       detail=detail(image), apart=apart)
            rows.append(row)
            print(f"| {frame} | {variant} | {seconds:.2f} | {row['energy']:.5g} | {warp:.4f} | {row['detail']:.4f} | "
                  f"{apart:.4f} |", flush=True)
    first = parse_frames(args.frames)[0]
    means = {}
    for variant in variants:
        later = [r for r in rows if r["variant"] == variant and r["frame"] != first]
        means[variant] = {k: float(np.mean([r[k] for r in later])) for k in ("seconds", "energy", "warp", "detail")}
    print("\nframes after the first, means:")
    for variant, m in means.items():
        ratio = means["cold"]["seconds"] / m["seconds"] if "cold" in means else float("nan")
        print(f"  {variant}: {m['seconds']:.2f} s ({ratio:.2f}x cold), final energy {m['energy']:.5g}, "
              f"warp error {m['warp']:.4f}, detail {m['detail']:.4f}")
    if args.json:
        Path(args.json).write_text(json.dumps({"args": vars(args), "rows": rows, "means": means}, indent=1))


if __name__ == "__main__":
    main()
