#!/usr/bin/env python3
"""Benchmark of the synthesis engine on a 1 Mpix target.

Inputs are generated procedurally (no outside data): analytically shaded
spheres on a table stand in for StyLit's light-path buffers (full, diffuse,
specular, indirect: four RGB guide pairs) and a hatching-like texture whose
density follows the source shading stands in for the painted exemplar (RGB
style). Default engine settings (budget usage, patch 5, automatic levels).

Prints and optionally writes JSON: wall time, peak memory (max RSS of the
process, and the engine's own: the peak RSS during synthesize() over the RSS
before it, with the kernel's peak reset in between), final energy and the
per-stage timings. (Free heap pages are returned to the system first, so the
engine cannot reuse them unseen.)

    PYTHONPATH=addon /usr/bin/python3 bench/bench_synthesis.py [--size 1024] [--json out.json]

With --sweep it runs 0.25, 1 and 4 Mpix (style and guides scaled together),
each in its own process, and reports time and memory per size and their
growth against 1 Mpix:

    PYTHONPATH=addon /usr/bin/python3 bench/bench_synthesis.py --sweep --json sweep.json

With --compare REV it builds the native module of git revision REV in a
temporary worktree and runs this checkout and REV alternately (--repeats
times each, every run in its own process), so that a speed-up is a ratio
measured side by side on the same, possibly noisy, machine:

    PYTHONPATH=addon /usr/bin/python3 bench/bench_synthesis.py --compare main~3 --repeats 3
"""
import argparse
import json
import platform
import resource
import time

import numpy as np

import tempera
from tempera.engine.synthesis import synthesize


def shade_scene(h, w, spheres):
    """Four RGB 'light-path buffers' of spheres (cx, cy, r, rgb) on a table."""
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    light = np.array([-0.5, -0.7, 0.6], np.float32)
    light /= np.linalg.norm(light)
    albedo = np.zeros((h, w, 3), np.float32) + np.array([0.8, 0.75, 0.7], np.float32)  # table
    normal = np.zeros((h, w, 3), np.float32) + np.array([0, -0.6, 0.8], np.float32)
    shadow = np.ones((h, w), np.float32)
    for cx, cy, r, rgb in spheres:
        dx, dy = (xx - cx) / r, (yy - cy) / r
        d2 = dx * dx + dy * dy
        inside = d2 < 1
        nz = np.sqrt(np.clip(1 - d2, 0, 1))
        normal[inside] = np.stack([dx, dy, nz], -1)[inside]
        albedo[inside] = rgb
        # soft contact shadow to the lower right on the table
        sd = ((xx - cx - 0.5 * r) / (1.3 * r)) ** 2 + ((yy - cy - 0.9 * r) / (0.5 * r)) ** 2
        shadow = np.minimum(shadow, np.where(inside, 1, np.clip(0.35 + 0.65 * sd, 0, 1)))
    ndotl = np.clip((normal * light).sum(-1), 0, 1) * shadow
    half = light + np.array([0, 0, 1], np.float32)
    half /= np.linalg.norm(half)
    spec = np.clip((normal * half).sum(-1), 0, 1) ** 40 * shadow
    indirect = 0.25 * (1 - normal[..., 2:3]) * albedo.mean(-1, keepdims=True)
    diffuse = albedo * ndotl[..., None]
    specular = np.repeat(spec[..., None], 3, -1)
    full = diffuse + specular + indirect * albedo
    return [full, diffuse, specular, indirect * np.ones_like(albedo)]


def hatching_style(full, seed=1):
    """A 'painted' exemplar: stroke density and colour follow the shading."""
    h, w, _ = full.shape
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    lum = full.mean(-1)
    strokes = 0.5 + 0.5 * np.sin((xx + yy) * 0.9 + rng.random((h, w)).astype(np.float32) * 1.5)
    ink = (strokes > lum * 1.2).astype(np.float32)
    paper = np.array([0.96, 0.93, 0.85], np.float32)
    pigment = np.array([0.15, 0.2, 0.45], np.float32)
    return (paper * (1 - ink[..., None]) + pigment * ink[..., None] * (0.6 + 0.4 * full)).astype(np.float32)


def benchmark_scene(s):
    """Source guides (one sphere), target guides (three spheres), style."""
    src = shade_scene(s, s, [(0.5 * s, 0.5 * s, 0.28 * s, (0.9, 0.9, 0.9))])
    tgt = shade_scene(s, s, [(0.3 * s, 0.35 * s, 0.18 * s, (0.9, 0.9, 0.9)),
                             (0.7 * s, 0.45 * s, 0.22 * s, (0.9, 0.9, 0.9)),
                             (0.45 * s, 0.75 * s, 0.12 * s, (0.9, 0.9, 0.9))])
    return src, tgt, hatching_style(src[0])


def guide_error(src, tgt, nnf):
    """Quality independent of engine settings: mean squared difference, over all
    twelve guide channels, between each target pixel and the source pixel its
    patch was copied from (lower = the style lands where the lighting matches)."""
    sx, sy = nnf[..., 0], nnf[..., 1]
    return float(np.mean([((a[sy, sx] - b) ** 2).sum(-1).mean() for a, b in zip(src, tgt)]))


ROOT = __import__("pathlib").Path(__file__).resolve().parent.parent


def build_revision(rev, folder):
    """The native module of `rev`, built in a worktree under `folder`; returns its addon folder."""
    import subprocess

    tree = folder / "tree"
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree), rev], check=True,
                   stdout=subprocess.DEVNULL)
    build = folder / "build"
    subprocess.run(["cmake", "-S", str(tree), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                    "-DTEMPERA_BUILD_TESTS=OFF"], check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", str(build), "--target", "_native", "-j", str(__import__("os").cpu_count())],
                   check=True, stdout=subprocess.DEVNULL)
    return tree / "addon"


def compare(args, rest):
    """This checkout against args.compare, alternating runs; prints medians and ratios."""
    import statistics
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory(prefix="tempera-bench-") as tmp:
        other = build_revision(args.compare, Path(tmp))
        try:
            runs = {"this": [], args.compare: []}
            for i in range(args.repeats):
                for name, addon in (("this", ROOT / "addon"), (args.compare, other)):
                    out = Path(tmp) / f"{i}-{len(runs[name])}.json"
                    env = dict(__import__("os").environ, PYTHONPATH=str(addon))
                    subprocess.run([sys.executable, __file__, *rest, "--json", str(out)], env=env, check=True,
                                   stdout=subprocess.DEVNULL)
                    runs[name].append(json.loads(out.read_text()))
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(Path(tmp) / "tree")])
    summary = {}
    for name, results in runs.items():
        summary[name] = {k: statistics.median(r[k] for r in results)
                         for k in ("wall_seconds", "cpu_seconds", "peak_rss_mb", "engine_peak_mb", "final_energy",
                                   "guide_error", "source_coverage", "budget_coverage", "finest_search_seconds")
                         if all(k in r for r in results)}
        summary[name]["wall_all"] = [r["wall_seconds"] for r in results]
    a, b = summary["this"], summary[args.compare]
    summary["ratio_this_over_other"] = {k: a[k] / b[k] for k in a if k in b and k != "wall_all"}
    print(json.dumps(summary, indent=1))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(summary, f, indent=1)


def rss_mb(field="VmRSS"):
    """Resident set size (or its peak, VmHWM) of this process in MB, from /proc."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1]) / 1024
    return float("nan")


def release_free_heap():
    """Returns freed heap memory to the system (glibc malloc_trim), so that the
    RSS before synthesize() holds no free pages the engine could reuse unseen."""
    import ctypes

    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass


def reset_peak_rss():
    """Resets VmHWM to the current RSS (Linux >= 4.0); False where not allowed."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


SWEEP_SIZES = (512, 1024, 2048)  # 0.25, 1 and 4 Mpix


def sweep(args, rest):
    """Each size in its own process; time and memory per size, and growth against 1 Mpix."""
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    rows = {}
    with tempfile.TemporaryDirectory(prefix="tempera-sweep-") as tmp:
        for size in SWEEP_SIZES:
            out = Path(tmp) / f"{size}.json"
            subprocess.run([sys.executable, __file__, *rest, "--size", str(size), "--json", str(out)], check=True,
                           stdout=subprocess.DEVNULL)
            rows[size] = json.loads(out.read_text())
    keys = ("wall_seconds", "cpu_seconds", "peak_rss_mb", "engine_peak_mb")
    base = rows[1024]
    summary = {"sizes": {str(s): {k: r[k] for k in (*keys, "final_energy", "guide_error", "source_coverage")}
                         for s, r in rows.items()},
               "growth_over_1mpix": {str(s): {k: r[k] / base[k] for k in keys} for s, r in rows.items()},
               "runs": {str(s): r for s, r in rows.items()}}
    print(json.dumps({k: summary[k] for k in ("sizes", "growth_over_1mpix")}, indent=1))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(summary, f, indent=1)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--compare", metavar="REV", help="also run git revision REV, alternately, and compare")
    parser.add_argument("--repeats", type=int, default=3, help="runs of each side with --compare")
    parser.add_argument("--size", type=int, default=1024, help="side of the square source and target")
    parser.add_argument("--usage", default="budget")
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--em-iters", type=int, default=6)
    parser.add_argument("--pm-iters", type=int, default=2)
    parser.add_argument("--guide-variance", type=float, default=0.999)
    parser.add_argument("--feature-precision", help="int16 or float (default: the engine's)")
    parser.add_argument("--skip-converged", choices=("true", "false"), help="default: the engine's")
    parser.add_argument("--sweep", action="store_true", help="0.25, 1 and 4 Mpix, each in its own process")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--json")
    args = parser.parse_args()
    rest = ["--usage", args.usage, "--threads", str(args.threads), "--em-iters", str(args.em_iters),
            "--pm-iters", str(args.pm_iters), "--guide-variance", str(args.guide_variance), "--seed", str(args.seed)]
    if args.feature_precision:
        rest += ["--feature-precision", args.feature_precision]
    if args.skip_converged:
        rest += ["--skip-converged", args.skip_converged]
    if args.sweep:
        return sweep(args, rest)
    if args.compare:
        return compare(args, ["--size", str(args.size), *rest])
    s = args.size
    src, tgt, style = benchmark_scene(s)
    guides = [(a, b, 1.0) for a, b in zip(src, tgt)]
    extra = {"feature_precision": args.feature_precision} if args.feature_precision else {}
    if args.skip_converged:
        extra["skip_converged"] = args.skip_converged == "true"
    release_free_heap()
    before_mb = rss_mb()
    peak_reset = reset_peak_rss()
    t0, cpu0 = time.perf_counter(), time.process_time()
    image, stats = synthesize(style, guides, usage=args.usage, threads=args.threads, em_iterations=args.em_iters,
                              pm_iterations=args.pm_iters, guide_variance=args.guide_variance, seed=args.seed, **extra)
    wall, cpu = time.perf_counter() - t0, time.process_time() - cpu0
    engine_peak_mb = (rss_mb("VmHWM") - before_mb) if peak_reset else float("nan")
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    finest = stats["levels"][-1]
    result = {
        "size": f"{s}x{s}",
        "usage": args.usage,
        "wall_seconds": round(wall, 2),
        "cpu_seconds": round(cpu, 2),
        "peak_rss_mb": round(peak_mb, 1),
        "engine_peak_mb": round(engine_peak_mb, 1),
        "rss_before_mb": round(before_mb, 1),
        "final_energy": finest["energy"][-1],
        "guide_error": guide_error(src, tgt, stats["nnf"]),
        # The error budget's own figure: the fraction of the finest frame that
        # reversed retrieval placed (the rest keeps its forward match).
        "budget_coverage": finest["reversed_coverage"],
        "finest_search_seconds": round(finest["search_seconds"], 2),
        "settings": {"em_iterations": args.em_iters, "pm_iterations": args.pm_iters,
                     "guide_variance": args.guide_variance, "threads": args.threads, "seed": args.seed,
                     "feature_precision": args.feature_precision or "default",
                     "skip_converged": args.skip_converged or "default"},
        "guide_channels_matched": stats["guide_channels"],
        # usage_wide_searches, converged_skips: absent in builds before they were counted (--compare).
        "levels": [{k: getattr(l, k) for k in ("width", "height", "search_seconds", "usage_seconds", "vote_seconds",
                                               "usage_rounds", "usage_wide_searches", "converged_skips", "reversed_coverage",
                                               "energy")
                    if hasattr(l, k)} for l in stats["levels"]],
        "source_coverage": stats["source_coverage"],
        "machine": f"{platform.processor() or platform.machine()}, {__import__('os').cpu_count()} cores",
        "tempera": tempera.__version__,
    }
    print(json.dumps(result, indent=1))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)
    tempera.write_image(f"/tmp/bench_style_{s}.png", style)
    tempera.write_image(f"/tmp/bench_out_{s}_{args.feature_precision or 'default'}.png", image)


if __name__ == "__main__":
    main()
