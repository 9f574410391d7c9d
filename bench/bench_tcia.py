#!/usr/bin/env python3
"""Seconds per frame of the coherent method (Bénard et al. 2013, tempera.methods.tcia.tcia)
on a synthetic panning shot, at a given size.

The shot: a camera panning `--speed` px per frame over shaded spheres on a
table (bench_synthesis.shade_scene: four light-path buffers as guides), so
V- = V+ = (-speed, 0) everywhere and a band of `speed` pixels enters (χ- = 0)
and leaves (χ+ = 0) at the edges; the exemplar is one sphere with a
hatching-like painting (bench_synthesis.hatching_style). The method's default
options (9 x 9 Gaussian window, automatic levels, one forward and one
backward sweep per level, 4 PatchMatch iterations per visit).

    PYTHONPATH=addon /usr/bin/python3 bench/bench_tcia.py --mpix 0.25 --frames 4 [--json out.json]

With `--layers N` the frame is also solved as N layers (vertical strips,
tempera.methods.tcia.tcia.stylize_layers: motion and guides extended past each strip, one
solve per layer) in the same run, beside the one-layer solve.

A rendered shot instead of the synthetic one (a guide cache and a painting
with its guides, as bench_warm_start.py reads them; no keys):

    PYTHONPATH=addon /usr/bin/python3 bench/bench_tcia.py --guides GUIDE_CACHE --frames 1-8 \
        --exemplar PAINTING --exemplar-pngs DIR [--exemplar-shrink 2] [--save DIR]

reports, besides the seconds, the warp error (mean colour change along the
motion where visible: the flicker) and the detail (mean gradient magnitude)
over the frames, and with --save writes them (frame_NNNN.png) to compare
revisions. `--set NAME=VALUE` (repeatable) passes an option, e.g.
`--set guide_variance=0.999`.
"""
import argparse
import json
import platform
import resource
import time

import numpy as np

from bench_synthesis import hatching_style, shade_scene
from tempera.methods.tcia import tcia


def panning_shot(side, frames, speed):
    """(style, [(name, exemplar guide, weight)], frames) of the coherent method."""
    wide = side + speed * frames
    spheres = [(0.2 * wide, 0.35 * side, 0.16 * side, (0.9, 0.85, 0.8)),
               (0.5 * wide, 0.6 * side, 0.22 * side, (0.8, 0.85, 0.9)),
               (0.8 * wide, 0.4 * side, 0.18 * side, (0.9, 0.9, 0.8))]
    world = shade_scene(side, wide, spheres)
    src = shade_scene(side, side, [(0.5 * side, 0.5 * side, 0.28 * side, (0.9, 0.9, 0.9))])
    names, weights = ("FULL", "LDE", "LSE", "LDDE"), (1.0, 2.0, 1.0, 0.5)
    v = np.zeros((side, side, 2), np.float32)
    v[..., 0] = -speed
    entering, leaving = np.ones((side, side), np.float32), np.ones((side, side), np.float32)
    entering[:, side - speed:], leaving[:, :speed] = 0, 0
    shot = [dict(guides=[np.ascontiguousarray(g[:, speed * t:speed * t + side]) for g in world],
                 velocity_backward=v, velocity_forward=v, occlusion_backward=entering, occlusion_forward=leaving)
            for t in range(frames)]
    return hatching_style(src[0]), list(zip(names, src, weights)), shot


def rendered_shot(args):
    """(style, guides, frames, frame numbers) of a guide cache and a painting with its guides."""
    from tempera import read_image
    from tempera.app import guide_cache
    from tempera.app.frames import parse_frames
    from tempera.app.settings import LIGHT_PATH_GUIDES
    from bench_warm_start import GUIDES, exemplar_from_pngs, shrink

    weights = {g["name"]: g["weight"] for g in LIGHT_PATH_GUIDES}  # the default guide weights
    style = np.asarray(read_image(args.exemplar), np.float32)[:, :, :3]
    exemplar = exemplar_from_pngs(args.exemplar_pngs)
    if args.exemplar_shrink > 1:
        style = shrink(style, args.exemplar_shrink)
        exemplar = {k: shrink(v, args.exemplar_shrink) for k, v in exemplar.items()}
    motion = ["velocity_backward", "occlusion_backward", "velocity_forward", "occlusion_forward"]
    frames, numbers = [], parse_frames(args.frames)
    for f in numbers:
        g = guide_cache.read_frame(args.guides, f, GUIDES + motion)
        frames.append(dict(guides=[g[n] for n in GUIDES], **{k: g[k] for k in motion}))
    return style, [(n, exemplar[n], weights[n]) for n in GUIDES], frames, numbers


def shot_quality(out, frames):
    """Mean warp error (frames after the first) and detail of the stylized frames."""
    from tempera.engine import temporal
    from bench_warm_start import detail

    warp = [temporal.flicker(out[t - 1], out[t], frames[t]["velocity_backward"], frames[t]["occlusion_backward"])
            for t in range(1, len(out))]
    return dict(warp_error=round(float(np.mean(warp)), 5), detail=round(float(np.mean([detail(o) for o in out])), 5))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mpix", type=float, default=0.25, help="frame size in megapixels (square)")
    parser.add_argument("--frames", default="4", help="how many (synthetic shot) or which (--guides: 1-8)")
    parser.add_argument("--speed", type=int, default=3, help="pan in pixels per frame")
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--layers", type=int, default=0, help="also solve as this many layers (strips)")
    parser.add_argument("--json", help="also write the figures here")
    parser.add_argument("--guides", help="a rendered shot's guide cache instead of the synthetic shot")
    parser.add_argument("--exemplar", help="with --guides: the painting")
    parser.add_argument("--exemplar-pngs", help="with --guides: the painting's guides, ebsynth's PNGs")
    parser.add_argument("--exemplar-shrink", type=int, default=1, help="box-downsample the exemplar k x k")
    parser.add_argument("--save", help="with --guides: write the frames here")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="a method or engine option (tcia.options), e.g. guide_variance=0.999; repeatable")
    args = parser.parse_args()
    if args.guides:
        style, guides, frames, numbers = rendered_shot(args)
        args.frames = len(frames)
    else:
        side, args.frames = int(round((args.mpix * 1e6) ** 0.5)), int(args.frames)
        style, guides, frames = panning_shot(side, args.frames, args.speed)
    height, width = frames[0]["guides"][0].shape[:2]
    started, cpu = time.monotonic(), time.process_time()
    values = {k: int(v) if v.lstrip("-").isdigit() else float(v) for k, v in (item.split("=", 1) for item in args.set)}
    out = tcia.stylize_shot(style, guides, frames, threads=args.threads, **values)
    wall, cpu = time.monotonic() - started, time.process_time() - cpu
    assert len(out) == args.frames
    quality = shot_quality(out, frames) if args.guides else {}
    if args.save:
        from pathlib import Path
        from tempera import write_image
        Path(args.save).mkdir(parents=True, exist_ok=True)
        for f, image in zip(numbers, out):
            write_image(str(Path(args.save) / f"frame_{f:04d}.png"), image)
    result = dict(**values, **quality, width=width, height=height, mpix=width * height / 1e6, frames=args.frames, wall_s=round(wall, 2), cpu_s=round(cpu, 2),
                  s_per_frame=round(wall / args.frames, 2),
                  peak_rss_mb=round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024),
                  machine=f"{platform.system()} {platform.machine()}, {__import__('os').cpu_count()} cores")
    if args.layers:
        strips = np.array_split(np.arange(width), args.layers)
        masks = [np.zeros((height, width), np.float32) for _ in strips]
        for m, cols in zip(masks, strips):
            m[:, cols] = 1
        started, cpu = time.monotonic(), time.process_time()
        tcia.stylize_layers(style, guides, frames, [([m] * args.frames, None) for m in masks], threads=args.threads)
        wall_layers, cpu = time.monotonic() - started, time.process_time() - cpu
        result.update(layers=args.layers, layers_wall_s=round(wall_layers, 2), layers_cpu_s=round(cpu, 2),
                      layers_s_per_frame=round(wall_layers / args.frames, 2))
    print(json.dumps(result, indent=2))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=2)


if __name__ == "__main__":
    main()
