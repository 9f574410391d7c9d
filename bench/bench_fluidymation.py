#!/usr/bin/env python3
"""Seconds per frame and peak memory of Fluidymation (tempera.methods.fluidymation.fluidymation)
at the paper's second size: a 500 x 600 target whose mask is a spreading
blob of about 60k pixels, and a 200 x 200 x 20 exemplar (ink rings on a
spreading disc, RGB + mask). The method's defaults (5 x 5 patches, b = 30,
3 EM iterations x 2 PatchMatch sweeps per level); the target's flow from its
masks (App. A). Frame 1 starts cold; the later frames start from SHIFTNNF of
the frame before, which is what a shot costs per frame.

    PYTHONPATH=addon /usr/bin/python3 bench/bench_fluidymation.py --frames 4 [--threads 2] [--em-iters 2 --pm-iters 1]
        [--json out.json]
"""
import argparse
import json
import os
import platform
import resource
import time

import numpy as np

from tempera.methods.fluidymation import fluidymation


def disc(h, w, radius, cx, cy):
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    return (np.hypot(xx - cx, yy - cy) <= radius).astype(np.float32)


def exemplar(side=200, frames=20):
    yy, xx = np.mgrid[0:side, 0:side].astype(np.float32)
    r = np.hypot(xx - side / 2, yy - side / 2)
    rng = np.random.default_rng(1)
    grain = rng.random((side, side), dtype=np.float32)
    rgb, masks = [], []
    for i in range(frames):
        radius = 20 + 3.5 * i
        ring = 0.5 + 0.5 * np.sin(2 * np.pi * (radius - r) / 9)
        rgb.append(np.stack([0.2 + 0.6 * ring, 0.3 + 0.2 * grain, 0.9 - 0.5 * ring], -1).astype(np.float32))
        masks.append((r <= radius).astype(np.float32))
    return rgb, masks


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--frames", type=int, default=4)
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--json")
    p.add_argument("--em-iters", type=int, help="engine EM iterations (default: the method's 3)")
    p.add_argument("--pm-iters", type=int, help="PatchMatch sweeps per search (default: the method's 2)")
    a = p.parse_args()
    extra = {k: v for k, v in (("em_iterations", a.em_iters), ("pm_iterations", a.pm_iters)) if v is not None}
    rgb, masks = exemplar()
    # 60k px: radius ~138 at the middle frame, spreading 2 px per frame.
    targets = [disc(600, 500, 134 + 2 * j, 250, 300) for j in range(a.frames)]
    stamps = []
    start = time.perf_counter()

    def progress(fraction):
        stamps.append((time.perf_counter(), fraction))

    cpu0 = resource.getrusage(resource.RUSAGE_SELF)
    frames = fluidymation.stylize_sequence(rgb, masks, targets, progress=progress, threads=a.threads, **extra)
    total = time.perf_counter() - start
    cpu1 = resource.getrusage(resource.RUSAGE_SELF)
    cpu = (cpu1.ru_utime + cpu1.ru_stime) - (cpu0.ru_utime + cpu0.ru_stime)
    # Per frame: from the progress reports crossing each frame boundary.
    ends = [next(t for t, f in stamps if f >= (j + 1) / a.frames - 1e-9) for j in range(a.frames)]
    per_frame = np.diff([start] + ends)
    result = {
        "machine": f"{platform.processor() or platform.machine()}, {platform.system()}",
        "target": "500x600", "mask_px": int(targets[a.frames // 2].sum()), "exemplar": "200x200x20",
        "threads": a.threads, "frames": a.frames, "options": extra, "total_s": round(total, 2),
        "cpu_s_per_frame": round(cpu / a.frames, 2), "load_average": round(os.getloadavg()[0], 1),
        "first_frame_s": round(float(per_frame[0]), 2),
        "later_frames_s": round(float(per_frame[1:].mean()), 2) if a.frames > 1 else None,
        "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1),
        "mean_energy": round(float(np.mean([f["energy"] for f in frames])), 4),
    }
    print(json.dumps(result, indent=1))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
