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
(cold, and warm-started) and with usage none, λ 3, the contrast-graded exemplar of the L2 test.

A shot, cold against warm-started frames (--shot GUIDE_CACHE --exemplar-frames
DIR, issue 32): each variant chained on its own previous frame (the advected
output of the temporal term, and for a warm start the previous frame's matches
advected along F^{t-1}); frame after frame the variants alternate, so both see
the same machine load. Variants: cold, warm, warm-emN (warm with N EM
iterations). Per frame and variant: seconds, the finest level's final energy
(the solver's objective), warp error (mean RGBA change against the previous
output advected, where both hold material: the flicker), detail (mean
gradient magnitude inside the target), interior contrast (the wash-out
measure above, where the target alpha is above 0.5).

    PYTHONPATH=addon /usr/bin/python3 bench/bench_lazyfluids.py --side 512 --frames 3 [--json out.json]
    PYTHONPATH=addon /usr/bin/python3 bench/bench_lazyfluids.py --washout 120 --side 48 --exemplar 24
    PYTHONPATH=addon /usr/bin/python3 bench/bench_lazyfluids.py --shot out/demo-fluids/chimney/guides \
        --exemplar-frames out/demo-fluids/exemplars/smoke --shot-frames 13-36 [--variants cold,warm] [--save DIR]
"""
import argparse
import json
import platform
import resource
import time

import numpy as np

from pathlib import Path

from tempera import read_image, write_image
from tempera.app import guide_cache
from tempera.app.frames import parse_frames
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


def interior_contrast(image, alpha, inside_above=0.99):
    from numpy.lib.stride_tricks import sliding_window_view
    windows = sliding_window_view(image[..., :3], (5, 5), axis=(0, 1))
    std = windows.std(axis=(-2, -1)).mean(axis=-1)
    inside = sliding_window_view(alpha, (5, 5)).min(axis=(-2, -1)) > inside_above
    return float(std[inside].mean()) if inside.any() else float("nan")


def detail(image, alpha):
    """Mean gradient magnitude of the RGB inside the target: what a smeared frame loses."""
    gy, gx = np.gradient(image[..., :3].mean(axis=2))
    inside = alpha > 0.5
    return float(np.hypot(gx, gy)[inside].mean()) if inside.any() else float("nan")


def warp_error(image, advected):
    """Mean RGBA change against the previous output advected, where both hold material."""
    both = (image[..., 3] > 0.5) & (advected[..., 3] > 0.5)
    return float(np.abs(image - advected)[both].mean()) if both.any() else float("nan")


def variant_options(name):
    """cold | warm | warm-emN."""
    if name == "cold":
        return dict(warm_start=False)
    if name == "warm":
        return dict(warm_start=True)
    if name.startswith("warm-em"):
        return dict(warm_start=True, em_iterations=int(name[len("warm-em"):]))
    raise SystemExit(f"unknown variant {name!r} (cold, warm, warm-emN)")


def shot(args):
    variants = args.variants.split(",")
    folder = Path(args.exemplar_frames)
    exemplar = [np.asarray(read_image(str(f)), np.float32) for f in sorted(folder.glob("frame_*.png"))]
    if not exemplar or exemplar[0].shape[2] != 4:
        raise SystemExit(f"{folder}: no RGBA frame_*.png")
    frames = parse_frames(args.shot_frames)
    state = {v: None for v in variants}  # previous output, field and flow per variant
    rows = []
    print("| frame | variant | seconds | final energy | warp error | detail | interior contrast |")
    print("| ---: | --- | ---: | ---: | ---: | ---: | ---: |")
    flow_previous = None
    for index, frame in enumerate(frames):
        guides = guide_cache.read_frame(args.shot, frame, ["alpha", "fluid_velocity"])
        alpha = np.asarray(guides["alpha"], np.float32).reshape(guides["fluid_velocity"].shape[:2])
        style, before = exemplar[index % len(exemplar)], exemplar[max(index - 1, 0) % len(exemplar)]
        for variant in variants:
            prev = state[variant]
            extra = {}
            if prev is not None:
                extra = dict(previous=prev["image"], flow_previous=flow_previous, previous_field=prev["field"])
            started = time.monotonic()
            image, stats = lazyfluids.stylize_frame(style, alpha, previous_style=before, threads=args.threads,
                                                    **variant_options(variant), **extra)
            seconds = time.monotonic() - started
            warp = warp_error(image, lazyfluids.advect_output(prev["image"], flow_previous)) if prev else float("nan")
            state[variant] = dict(image=image, field=stats["field"])
            if args.save:
                Path(args.save).mkdir(parents=True, exist_ok=True)
                write_image(str(Path(args.save) / f"{variant}_{frame:04d}.png"), np.clip(image, 0, 1))
            row = dict(frame=frame, variant=variant, seconds=seconds, energy=stats["final_energy"], warp=warp,
                       detail=detail(image, alpha), contrast=interior_contrast(image, alpha, 0.5))
            rows.append(row)
            print(f"| {frame} | {variant} | {seconds:.2f} | {row['energy']:.5g} | {warp:.4f} | {row['detail']:.4f} | "
                  f"{row['contrast']:.4f} |", flush=True)
        flow_previous = guides["fluid_velocity"]
    means = {}
    keys = ("seconds", "energy", "warp", "detail", "contrast")
    for variant in variants:
        later = [r for r in rows if r["variant"] == variant and r["frame"] != frames[0]]
        means[variant] = {k: float(np.nanmean([r[k] for r in later])) for k in keys}
    print("\nframes after the first, means:")
    for variant, m in means.items():
        ratio = means["cold"]["seconds"] / m["seconds"] if "cold" in means else float("nan")
        print(f"  {variant}: {m['seconds']:.2f} s ({ratio:.2f}x cold), final energy {m['energy']:.5g}, "
              f"warp error {m['warp']:.4f}, detail {m['detail']:.4f}, interior contrast {m['contrast']:.4f}")
    return dict(rows=rows, means=means)


def washout(args):
    alpha, flow = rotating_disc(args.side, 0.08)
    out = {}
    for name, usage, warm in (("uniform", "uniform", False), ("uniform, warm start", "uniform", True),
                              ("none", "none", False)):
        t0 = time.perf_counter()
        frames = lazyfluids.stylize_sequence(graded_smoke(args.exemplar), [alpha] * args.washout,
                                             [flow] * args.washout, usage=usage, temporal_weight=3.0, em_iterations=3,
                                             warm_start=warm)
        c1, c10, last = (interior_contrast(frames[i], alpha) for i in (0, 9, -1))
        out[name] = dict(c1=c1, c10=c10, c_last=last, seconds=time.perf_counter() - t0)
        print(f"{name}: C(1) {c1:.4f}  C(10) {c10:.4f}  C({args.washout}) {last:.4f}  C(N)/C(1) {last / c1:.3f}"
              f"  C(N)/C(10) {last / c10:.3f}  ({out[name]['seconds']:.1f} s)")
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
    parser.add_argument("--shot", help="a guide cache (alpha, fluid_velocity): cold against warm frames")
    parser.add_argument("--exemplar-frames", help="with --shot: a folder of RGBA frame_NNNN.png (a video exemplar)")
    parser.add_argument("--shot-frames", default="1-8", help="with --shot: the cache's frames")
    parser.add_argument("--variants", default="cold,warm", help="with --shot: cold, warm, warm-emN")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--save", help="with --shot: each variant's frames as VARIANT_NNNN.png")
    parser.add_argument("--json", help="write the results here")
    args = parser.parse_args()
    result = shot(args) if args.shot else washout(args) if args.washout else speed(args)
    result["machine"] = f"{platform.platform()}, {__import__('os').cpu_count()} cores"
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=2)


if __name__ == "__main__":
    main()
