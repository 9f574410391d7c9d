#!/usr/bin/env python3
"""LazyFluids (tempera.methods.lazyfluids.lazyfluids): seconds per frame, and the 120-frame
wash-out run of the issue.

Speed: a `--side`² target (default 512²) whose alpha is a disc of radius
0.4 side turning at 0.02 rad per frame (rotational flow about its centre),
from a `--exemplar`² smoke-like exemplar (default 128²: smoothed noise in
RGB, a soft alpha disc), the method's defaults (5 x 5 patches, uniform usage,
λ 0.2), all cores.

Wash-out (--washout N): N frames of the same rotation on a small target; the
interior 5x5 local contrast C of frames 1, 10 and the last, with uniform usage
and with usage none, λ 3, the contrast-graded exemplar of the L2 test.

    PYTHONPATH=addon /usr/bin/python3 bench/bench_lazyfluids.py --side 512 --frames 3 [--json out.json]
    PYTHONPATH=addon /usr/bin/python3 bench/bench_lazyfluids.py --washout 120 --side 48 --exemplar 24
"""
import argparse
import json
import platform
import resource
import time

import numpy as np

from tempera.methods.lazyfluids import lazyfluids


def smoke(n, seed=1):
    """Smoothed noise in RGB, a soft alpha disc."""
    rng = np.random.default_rng(seed)
    noise = rng.random((n, n, 3))
    k = np.exp(-0.5 * (np.arange(-2, 3) / 0.7) ** 2)
    k /= k.sum()
    for axis in (0, 1):
        noise = np.apply_along_axis(lambda v: np.convolve(np.pad(v, 2, mode="edge"), k, "valid"), axis, noise)
    yy, xx = np.mgrid[0:n, 0:n]
    alpha = np.clip((0.42 * n - np.hypot(xx - (n - 1) / 2, yy - (n - 1) / 2)) / 1.5, 0, 1)
    return np.dstack([np.clip(0.5 + 2 * (noise - 0.5), 0, 1), alpha]).astype(np.float32)


def graded_smoke(n, seed=6):
    """Noise whose contrast grows from left (smooth) to right: without a usage
    rule the smooth side wins more and more of the frame (the L2 test's)."""
    rng = np.random.default_rng(seed)
    out = smoke(n, seed)
    amp = (0.15 + 1.6 * np.arange(n) / (n - 1))[None, :, None]
    out[..., :3] = np.clip(0.5 + amp * (rng.random((n, n, 3)) - 0.5), 0, 1)
    return out


def rotating_disc(side, omega):
    yy, xx = np.mgrid[0:side, 0:side].astype(np.float32)
    c = (side - 1) / 2
    alpha = np.clip(0.4 * side - np.hypot(xx - c, yy - c) + 0.5, 0, 1).astype(np.float32)
    dx, dy = xx - c, yy - c
    flow = np.dstack([np.cos(omega) * dx - np.sin(omega) * dy - dx, np.sin(omega) * dx + np.cos(omega) * dy - dy])
    return alpha, flow.astype(np.float32)


def interior_contrast(image, alpha):
    from numpy.lib.stride_tricks import sliding_window_view
    windows = sliding_window_view(image[..., :3], (5, 5), axis=(0, 1))
    std = windows.std(axis=(-2, -1)).mean(axis=-1)
    inside = sliding_window_view(alpha, (5, 5)).min(axis=(-2, -1)) > 0.99
    return float(std[inside].mean())


def washout(args):
    alpha, flow = rotating_disc(args.side, 0.08)
    out = {}
    for usage in ("uniform", "none"):
        t0 = time.perf_counter()
        frames = lazyfluids.stylize_sequence(graded_smoke(args.exemplar), [alpha] * args.washout,
                                             [flow] * args.washout, usage=usage, temporal_weight=3.0, em_iterations=3)
        c1, c10, last = (interior_contrast(frames[i], alpha) for i in (0, 9, -1))
        out[usage] = dict(c1=c1, c10=c10, c_last=last, seconds=time.perf_counter() - t0)
        print(f"{usage}: C(1) {c1:.4f}  C(10) {c10:.4f}  C({args.washout}) {last:.4f}  C(N)/C(1) {last / c1:.3f}"
              f"  C(N)/C(10) {last / c10:.3f}  ({out[usage]['seconds']:.1f} s)")
    return out


def speed(args):
    alpha, flow = rotating_disc(args.side, 0.02)
    t0, c0 = time.perf_counter(), time.process_time()
    lazyfluids.stylize_sequence(smoke(args.exemplar), [alpha] * args.frames, [flow] * args.frames,
                                warm_start=args.warm_start)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    result = dict(side=args.side, exemplar=args.exemplar, frames=args.frames, warm_start=args.warm_start,
                  wall=wall, cpu=cpu,
                  seconds_per_frame=wall / args.frames,
                  peak_rss_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
    print(f"{args.side}² from {args.exemplar}²{' (warm start)' if args.warm_start else ''}: {args.frames} frames in {wall:.1f} s wall, {cpu:.1f} s CPU: "
          f"{wall / args.frames:.2f} s per frame, peak RSS {result['peak_rss_mb']:.0f} MB")
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--side", type=int, default=512, help="target side in pixels")
    parser.add_argument("--exemplar", type=int, default=128, help="exemplar side in pixels")
    parser.add_argument("--frames", type=int, default=3)
    parser.add_argument("--washout", type=int, default=0, help="frames of the wash-out run (0: the speed run)")
    parser.add_argument("--warm-start", action="store_true", help="frames after the first from the advected field")
    parser.add_argument("--json", help="write the results here")
    args = parser.parse_args()
    result = washout(args) if args.washout else speed(args)
    result["machine"] = f"{platform.platform()}, {__import__('os').cpu_count()} cores"
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=2)


if __name__ == "__main__":
    main()
